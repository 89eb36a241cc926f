#pragma once
// Answers a file_request_t for a stored session's product files (the LCM
// endpoint's thread calls it): the chunks asked for, or one chunk with the
// error. Only the paths protocol::product_path_problem() accepts are read,
// from the session's own folder; "products/" answers the list of those
// present. At most protocol::kMaxChunksPerRequest chunks per request.

#include <filesystem>
#include <functional>
#include <string>

#include "adit/file_chunk_t.hpp"
#include "adit/file_request_t.hpp"

namespace adit::daemon {

// `session` is the session answered for (the request's, or the daemon's last
// when it named none); `folder` maps a session name to its folder (empty
// function: no stored sessions). Returns the chunks sent.
std::size_t answer_file_request(const file_request_t& request, const std::string& session,
                                const std::function<std::filesystem::path(const std::string&)>& folder,
                                const std::function<void(const file_chunk_t&)>& send);

}  // namespace adit::daemon
