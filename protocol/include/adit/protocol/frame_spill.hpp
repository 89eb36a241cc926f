#pragma once
// Byte frames kept on disk instead of in RAM: an unnamed temporary file
// (O_TMPFILE, gone with the last descriptor, even after a crash) that frames
// are appended to and read back from with pread. A frame's bytes are freed
// (a hole punched, fallocate(2) FALLOC_FL_PUNCH_HOLE) when the last holder of
// its SpilledFrame lets it go, so the disk holds what is live, not every
// frame ever written. A follower of a long session (adit console) then holds
// the map in the page cache, which the kernel may drop, not in its heap.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

namespace adit::protocol {

class SpilledFrame;

class FrameSpill : public std::enable_shared_from_this<FrameSpill> {
  struct Key {  // only the spill makes one: open() and write() alone construct
    explicit Key() = default;
  };

 public:
  // A spill file in `dir`; throws adit::InputError naming the folder when it
  // cannot make one there.
  static std::shared_ptr<FrameSpill> open(const std::filesystem::path& dir);
  FrameSpill(Key, int fd);
  ~FrameSpill();
  FrameSpill(const FrameSpill&) = delete;
  FrameSpill& operator=(const FrameSpill&) = delete;

  // The frame written at the file's end, or nullptr when it could not be
  // written (the disk full): the caller keeps it in memory then.
  std::shared_ptr<const SpilledFrame> write(std::span<const std::uint8_t> frame);

  std::uint64_t live_bytes() const { return live_bytes_.load(std::memory_order_relaxed); }
  // The file's blocks on disk (fstat's st_blocks): about live_bytes where holes can be punched.
  std::uint64_t disk_bytes() const;
  std::uint64_t failed_writes() const { return failed_writes_.load(std::memory_order_relaxed); }
  std::uint64_t failed_reads() const { return failed_reads_.load(std::memory_order_relaxed); }

 private:
  friend class SpilledFrame;
  void release(std::uint64_t offset, std::uint32_t size);

  int fd_;
  std::atomic<std::uint64_t> end_{0};  // where the next frame goes (writers take their range first)
  std::atomic<std::uint64_t> live_bytes_{0};
  std::atomic<std::uint64_t> failed_writes_{0};
  mutable std::atomic<std::uint64_t> failed_reads_{0};  // counted by SpilledFrame::read
};

// One frame in a spill file; its bytes are freed when it is destroyed.
class SpilledFrame {
 public:
  // Made by FrameSpill::write only (its Key).
  SpilledFrame(FrameSpill::Key, std::shared_ptr<FrameSpill> file, std::uint64_t offset, std::uint32_t size);
  ~SpilledFrame();
  SpilledFrame(const SpilledFrame&) = delete;
  SpilledFrame& operator=(const SpilledFrame&) = delete;

  // The frame's bytes into `out` (resized); false, and counted in the
  // file's failed_reads(), when the file cannot be read.
  bool read(std::vector<std::uint8_t>& out) const;

 private:
  std::shared_ptr<FrameSpill> file_;
  std::uint64_t offset_;
  std::uint32_t size_;
};

}  // namespace adit::protocol
