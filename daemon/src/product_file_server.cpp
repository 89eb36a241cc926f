#include "adit/daemon/product_file_server.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <vector>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/protocol/product_files.hpp"

namespace adit::daemon {
namespace {

bool plain_session_name(const std::string& id) {
  return !id.empty() && id.size() <= 64 && id.front() != '.' && std::all_of(id.begin(), id.end(), [](char c) {
           return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_';
         });
}

// Product files present under the session folder, one relative path a line.
std::string product_list(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (auto it = std::filesystem::recursive_directory_iterator(dir / "products", ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const std::string name = "products/" + std::filesystem::relative(it->path(), dir / "products", ec).generic_string();
    if (protocol::product_path_problem(name).empty()) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::string text;
  for (const std::string& n : names) text += n + "\n";
  return text;
}

}  // namespace

std::size_t answer_file_request(const file_request_t& request, const std::string& session,
                                const std::function<std::filesystem::path(const std::string&)>& folder,
                                const std::function<void(const file_chunk_t&)>& send) {
  file_chunk_t c;
  c.utime = realtime_us();
  c.schema = 1;
  c.request_id = request.request_id;
  c.payload_id = request.payload_id;
  c.session_id = session;
  c.path = request.path.substr(0, 200);
  c.file_size = 0;
  c.n_chunks = 0;
  c.chunk = 0;
  c.size = 0;
  const auto fail = [&](std::string why) {
    c.error = std::move(why);
    send(c);
    return std::size_t{1};
  };
  if (session.empty()) return fail("no session has run yet: name one");
  if (!plain_session_name(session)) return fail(fmt::format("'{}' is not a session name", session.substr(0, 80)));
  if (const std::string problem = protocol::product_path_problem(request.path); !problem.empty()) return fail(problem);
  if (!folder) return fail(fmt::format("session '{}' is not held by this daemon", session));
  const std::filesystem::path dir = folder(session);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return fail(fmt::format("no session '{}'", session));
  if (!std::filesystem::is_directory(dir / "products", ec))
    return fail(fmt::format("session '{}' has no products (yet): aditd makes them after STOP", session));

  std::string listing;
  std::ifstream file;
  std::uint64_t size = 0;
  if (request.path == protocol::kProductListPath) {
    listing = product_list(dir);
    size = listing.size();
  } else {
    file.open(dir / request.path, std::ios::binary);
    if (!file) return fail(fmt::format("session '{}' has no {}", session, request.path));
    file.seekg(0, std::ios::end);
    size = static_cast<std::uint64_t>(file.tellg());
  }
  c.file_size = static_cast<std::int64_t>(size);
  c.n_chunks = protocol::file_chunk_count(size);
  const std::int32_t first = std::clamp(request.first_chunk, 0, c.n_chunks);
  const std::int32_t count = std::clamp(request.n_chunks, 0, protocol::kMaxChunksPerRequest);
  const std::int32_t end = static_cast<std::int32_t>(std::min<std::int64_t>(c.n_chunks, std::int64_t{first} + count));
  std::size_t sent = 0;
  for (std::int32_t k = first; k < end; ++k) {
    const std::uint64_t offset = static_cast<std::uint64_t>(k) * protocol::kFileChunkBytes;
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(protocol::kFileChunkBytes, size - offset));
    c.chunk = k;
    c.data.resize(n);
    if (!listing.empty() || request.path == protocol::kProductListPath) {
      std::copy_n(listing.begin() + static_cast<std::ptrdiff_t>(offset), n, c.data.begin());
    } else {
      file.seekg(static_cast<std::streamoff>(offset));
      file.read(reinterpret_cast<char*>(c.data.data()), static_cast<std::streamsize>(n));
      if (!file) return sent + fail(fmt::format("session '{}': {} could not be read", session, request.path));
    }
    c.size = static_cast<std::int32_t>(n);
    send(c);
    ++sent;
  }
  return sent;
}

}  // namespace adit::daemon
