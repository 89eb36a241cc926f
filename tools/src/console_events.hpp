#pragma once
// adit console: the fan-out of live events to browsers (Server-Sent Events).
// Producers publish named events with JSON data; each browser's stream reads
// the events after the last id it has, waiting when there is none. The last
// `capacity` events are kept, so a browser that reconnects with its
// Last-Event-ID resumes where it stopped; one that fell further behind is
// told to resynchronise (it fetches the snapshot again).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace adit::tools::console {

struct Event {
  std::uint64_t id = 0;
  std::string name;  // pose, status, tiles, link, session, download, command
  std::string data;  // one line of JSON
};

// The SSE wire form of an event ("id: <instance>.<id>\nevent: ..\ndata: ..\n\n"); the
// instance tells a restarted console's ids from the last one's.
std::string sse_frame(const Event& event, std::string_view instance);
// The event id after which to resume for a Last-Event-ID from this `instance`, or nullopt.
std::optional<std::uint64_t> resume_after(std::string_view last_event_id, std::string_view instance);

class EventHub {
 public:
  explicit EventHub(std::size_t capacity = 2048) : capacity_(capacity) {}

  void publish(std::string_view name, std::string data);

  struct Batch {
    std::vector<Event> events;
    bool lost = false;  // events after `after` were already dropped: resynchronise
  };
  // The events after id `after`, waiting up to `timeout` for one; returns
  // early (empty) when closed.
  Batch wait_after(std::uint64_t after, std::chrono::milliseconds timeout) const;
  std::uint64_t last_id() const;
  // Wakes every waiting stream for good (server shutdown).
  void close();
  bool closed() const;

 private:
  std::size_t capacity_;
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::deque<Event> events_;
  std::uint64_t next_id_ = 1;
  bool closed_ = false;
};

}  // namespace adit::tools::console
