#include "adit/daemon/products_worker.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <exception>

#include "adit/common/log.hpp"
#include "adit/products/session_join_files.hpp"
#include "adit/products/session_products.hpp"

namespace adit::daemon {
namespace {

// SCHED_IDLE (sched(7)): below every nice level; needs no privilege. Nice 19
// when the kernel refuses it.
void lower_priority() {
  sched_param param{};
  param.sched_priority = 0;
  if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &param) == 0) return;
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19) != 0)
    log::warn("products: cannot lower the thread's priority");
}

}  // namespace

ProductsWorker::ProductsWorker(AfterSessionSteps steps) : steps_(steps), thread_([this] { run(); }) {}

ProductsWorker::~ProductsWorker() { stop(); }

void ProductsWorker::enqueue(std::filesystem::path session_dir) {
  {
    const std::lock_guard lock(mutex_);
    if (stopping_) return;
    queue_.push_back(std::move(session_dir));
  }
  changed_.notify_all();
}

void ProductsWorker::stop() {
  {
    const std::lock_guard lock(mutex_);
    if (!queue_.empty())
      log::warn("products: {} session(s) left without products at shutdown ({} first; `adit products` makes them)",
                queue_.size(), queue_.front().string());
    queue_.clear();
    stopping_ = true;
    if (busy_) {
      cancel_ = true;
      // Back to normal priority so the check is reached on a busy machine (EPERM for an unprivileged
      // thread without RLIMIT_NICE: it then reaches it at idle priority).
      sched_param param{};
      param.sched_priority = 0;
      if (thread_.joinable()) (void)pthread_setschedparam(thread_.native_handle(), SCHED_OTHER, &param);
    }
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ProductsWorker::wait_idle() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return (queue_.empty() && !busy_) || stopping_; });
}

std::size_t ProductsWorker::made() const {
  const std::lock_guard lock(mutex_);
  return made_;
}

std::size_t ProductsWorker::cancelled() const {
  const std::lock_guard lock(mutex_);
  return cancelled_;
}

std::size_t ProductsWorker::joined() const {
  const std::lock_guard lock(mutex_);
  return joined_;
}

std::size_t ProductsWorker::failed() const {
  const std::lock_guard lock(mutex_);
  return failed_;
}

void ProductsWorker::run() {
  pthread_setname_np(pthread_self(), "adit-products");
  lower_priority();
  while (true) {
    std::filesystem::path dir;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, nothing begun
      dir = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    if (steps_.products) make_products(dir);
    if (steps_.join_previous && !cancel_) join_previous(dir);
    {
      const std::lock_guard lock(mutex_);
      busy_ = false;
    }
    changed_.notify_all();
  }
}

void ProductsWorker::make_products(const std::filesystem::path& dir) {
  enum class Outcome { made, failed, cancelled } outcome = Outcome::failed;
  const std::filesystem::path partial = dir / "products.partial";
  const std::filesystem::path done = dir / "products";
  try {
    std::filesystem::remove_all(partial);  // a run cut short before
    products::ProductsOptions options;
    options.cancel = &cancel_;
    const products::ProductsReport r = products::write_session_products(dir, options, partial);
    std::filesystem::remove_all(done);
    std::filesystem::rename(partial, done);
    log::info("session {}: products in {} ({:.1f} s of CPU; {} targets{})", dir.filename().string(), done.string(),
              r.cpu_s, r.targets, r.targets_note.empty() ? "" : "; " + r.targets_note);
    outcome = Outcome::made;
  } catch (const products::Cancelled&) {
    log::warn("session {}: products cancelled at shutdown (`adit products` makes them)", dir.filename().string());
    outcome = Outcome::cancelled;
    std::error_code ec;
    std::filesystem::remove_all(partial, ec);
  } catch (const std::exception& e) {
    log::error("session {}: products failed: {}", dir.filename().string(), e.what());
    std::error_code ec;
    std::filesystem::remove_all(partial, ec);
  }
  const std::lock_guard lock(mutex_);
  (outcome == Outcome::made ? made_ : outcome == Outcome::failed ? failed_ : cancelled_) += 1;
}

void ProductsWorker::join_previous(const std::filesystem::path& dir) {
  const std::string name = dir.filename().string();
  products::JoinFilesOptions options;
  options.config = steps_.join;
  options.cancel = &cancel_;
  const std::vector<products::JoinFilesReport> reports = products::join_previous_session(dir, 3, options);
  if (reports.empty()) log::info("session {}: no earlier session with a map to join to", name);
  for (const products::JoinFilesReport& r : reports) {
    if (r.result.success) {
      log::info("session {}: joined to {} ({} of {} places agree, overlap {:.2f}; {})", name, r.stored_name,
                r.result.places_agreeing, r.result.places_tried, r.result.overlap, products::kJoinedFile);
      const std::lock_guard lock(mutex_);
      ++joined_;
    } else {
      log::info("session {}: not joined to {}: {}", name, r.stored_name, r.result.failure);
    }
  }
}

}  // namespace adit::daemon
