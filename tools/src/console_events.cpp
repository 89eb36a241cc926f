#include "console_events.hpp"

#include <charconv>

#include <fmt/format.h>

namespace adit::tools::console {

std::string sse_frame(const Event& event, std::string_view instance) {
  return fmt::format("id: {}.{}\nevent: {}\ndata: {}\n\n", instance, event.id, event.name, event.data);
}

std::optional<std::uint64_t> resume_after(std::string_view last_event_id, std::string_view instance) {
  const std::size_t dot = last_event_id.rfind('.');
  if (dot == std::string_view::npos || last_event_id.substr(0, dot) != instance) return std::nullopt;
  const std::string_view digits = last_event_id.substr(dot + 1);
  std::uint64_t id = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), id);
  if (error != std::errc() || end != digits.data() + digits.size()) return std::nullopt;
  return id;
}

void EventHub::publish(std::string_view name, std::string data) {
  {
    const std::lock_guard lock(mutex_);
    events_.push_back({next_id_++, std::string(name), std::move(data)});
    while (events_.size() > capacity_) events_.pop_front();
  }
  changed_.notify_all();
}

EventHub::Batch EventHub::wait_after(std::uint64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, timeout, [&] { return closed_ || (next_id_ - 1) > after; });
  Batch batch;
  if (closed_) return batch;
  if (!events_.empty() && events_.front().id > after + 1) batch.lost = true;
  for (const Event& e : events_)
    if (e.id > after) batch.events.push_back(e);
  return batch;
}

std::uint64_t EventHub::last_id() const {
  const std::lock_guard lock(mutex_);
  return next_id_ - 1;
}

void EventHub::close() {
  {
    const std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

bool EventHub::closed() const {
  const std::lock_guard lock(mutex_);
  return closed_;
}

}  // namespace adit::tools::console
