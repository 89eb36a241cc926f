#include "adit/protocol/frame_spill.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "adit/common/error.hpp"

namespace adit::protocol {

SpilledFrame::SpilledFrame(FrameSpill::Key, std::shared_ptr<FrameSpill> file, std::uint64_t offset, std::uint32_t size)
    : file_(std::move(file)), offset_(offset), size_(size) {}

SpilledFrame::~SpilledFrame() { file_->release(offset_, size_); }

bool SpilledFrame::read(std::vector<std::uint8_t>& out) const {
  out.resize(size_);
  std::size_t done = 0;
  while (done < size_) {
    const ssize_t n = ::pread(file_->fd_, out.data() + done, size_ - done, static_cast<off_t>(offset_ + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      file_->failed_reads_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::shared_ptr<FrameSpill> FrameSpill::open(const std::filesystem::path& dir) {
  // Unnamed where the file system allows it; otherwise named, then unlinked at once.
  int fd = ::open(dir.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd < 0) {
    std::string name = (dir / "adit-spill-XXXXXX").string();
    fd = ::mkostemp(name.data(), O_CLOEXEC);
    if (fd >= 0) ::unlink(name.c_str());
  }
  if (fd < 0) throw InputError(dir.string(), "", std::string("cannot make a spill file: ") + std::strerror(errno));
  return std::make_shared<FrameSpill>(Key{}, fd);
}

FrameSpill::FrameSpill(Key, int fd) : fd_(fd) {}

FrameSpill::~FrameSpill() { ::close(fd_); }

std::shared_ptr<const SpilledFrame> FrameSpill::write(std::span<const std::uint8_t> frame) {
  const auto size = static_cast<std::uint32_t>(frame.size());
  const std::uint64_t offset = end_.fetch_add(size, std::memory_order_relaxed);
  std::size_t done = 0;
  while (done < frame.size()) {
    const ssize_t n = ::pwrite(fd_, frame.data() + done, frame.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {  // ENOSPC, EIO: whatever part was written is freed again
      failed_writes_.fetch_add(1, std::memory_order_relaxed);
      if (done > 0) ::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(offset),
                                static_cast<off_t>(done));
      return nullptr;
    }
    done += static_cast<std::size_t>(n);
  }
  live_bytes_.fetch_add(size, std::memory_order_relaxed);
  return std::make_shared<const SpilledFrame>(Key{}, shared_from_this(), offset, size);
}

std::uint64_t FrameSpill::disk_bytes() const {
  struct stat st {};
  return ::fstat(fd_, &st) == 0 ? static_cast<std::uint64_t>(st.st_blocks) * 512 : 0;
}

void FrameSpill::release(std::uint64_t offset, std::uint32_t size) {
  live_bytes_.fetch_sub(size, std::memory_order_relaxed);
  // Where holes cannot be punched (EOPNOTSUPP) the file only grows, as an append-only log would.
  ::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE, static_cast<off_t>(offset), static_cast<off_t>(size));
}

}  // namespace adit::protocol
