// adit download: assembles a session's map from the payload's tiles over LCM,
// re-requesting whatever was lost, and writes it as PLY, PCD or LAS; or, with
// --products / --product, fetches the session's product files (top view,
// grid, octree, sections, targets) into a folder (file_request_t).

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/product_files.hpp"
#include "client_options.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

struct DownloadOptions {
  ClientOptions client;
  std::string session;
  std::string format;
  std::string out;
  bool quiet = false;
  bool all_products = false;
  std::vector<std::string> products;  // names under products/ (top_view.png, sections/section_001.svg, ...)
};

void draw_progress(std::size_t have, std::size_t wanted) {
  constexpr int kWidth = 30;
  const double fraction = wanted == 0 ? 0.0 : static_cast<double>(have) / static_cast<double>(wanted);
  const int filled = static_cast<int>(fraction * kWidth);
  fmt::print(stderr, "\r[{}{}] {:3.0f}% {}/{} segments", std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(kWidth - filled), ' '), 100 * fraction, have, wanted);
}

// "top_view.png" or "products/top_view.png" -> "products/top_view.png".
std::string product_path(const std::string& name) {
  return name.rfind("products/", 0) == 0 ? name : "products/" + name;
}

int download_products(const DownloadOptions& o) {
  std::vector<std::string> paths;
  for (const std::string& name : o.products) {
    const std::string path = product_path(name);
    if (const std::string problem = protocol::product_path_problem(path); !problem.empty() || path == protocol::kProductListPath)
      throw InputError("--product", "", problem.empty() ? "names a file, not the list" : problem);
    paths.push_back(path);
  }
  LcmClient client(o.client);
  std::string session = o.session;
  if (o.all_products) {
    const LcmClient::FileResult list = client.fetch_file(session, std::string(protocol::kProductListPath));
    if (!list.ok) {
      fmt::print(stderr, "adit: error: download failed: {}\n", list.error);
      return kExitFailure;
    }
    session = list.session;
    for (std::size_t at = 0; at < list.bytes.size();) {
      const std::size_t end = list.bytes.find('\n', at);
      const std::string line = list.bytes.substr(at, end == std::string::npos ? std::string::npos : end - at);
      if (!line.empty() && protocol::product_path_problem(line).empty() && line != protocol::kProductListPath)
        paths.push_back(line);
      at = end == std::string::npos ? list.bytes.size() : end + 1;
    }
  }
  const std::filesystem::path out = o.out;
  std::uintmax_t total = 0;
  for (const std::string& path : paths) {
    const LcmClient::FileResult f = client.fetch_file(session, path);
    if (!f.ok) {
      fmt::print(stderr, "adit: error: {}: download failed: {}\n", path, f.error);
      return kExitFailure;
    }
    session = f.session;
    const std::filesystem::path file = out / std::filesystem::path(path).lexically_relative("products");
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary).write(f.bytes.data(), static_cast<std::streamsize>(f.bytes.size()));
    total += f.bytes.size();
    if (!o.quiet) fmt::print(stderr, "{} ({} bytes, {} requests)\n", path, f.bytes.size(), f.requests);
  }
  fmt::print("{} product files of session {} ({} bytes) written to {}\n", paths.size(), session, total, out.string());
  return kExitOk;
}

}  // namespace

void register_download_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<DownloadOptions>();
  CLI::App* sub = app.add_subcommand("download", "Fetch a session's map from the payload and write it to a file");
  add_client_options(*sub, o->client);
  sub->add_option("--session", o->session, "Session id (default: the payload's current or last session)");
  sub->add_option("--format", o->format, "Output format of the map: ply, pcd or las")
      ->check(CLI::IsMember({"ply", "pcd", "las"}));
  sub->add_flag("--products", o->all_products, "Fetch every product file of the session (made after STOP) into --out DIR");
  sub->add_option("--product", o->products, "Fetch this product file into --out DIR (top_view.png, grid.pgm, "
                                             "grid.yaml, occupancy.bt, sections/section_001.svg, ...); repeatable");
  sub->add_option("--out", o->out, "Output file (map) or folder (products)")->required();
  sub->add_flag("--quiet", o->quiet, "No progress bar");
  sub->callback([o, &status] {
    if (o->all_products || !o->products.empty()) {
      if (!o->format.empty()) throw InputError("--format", "", "is for the map; products are fetched as they are");
      status = download_products(*o);
      return;
    }
    if (o->format.empty()) throw InputError("--format", "", "required for the map (ply, pcd or las), or give --products");
    const protocol::MapFormat format = *protocol::parse_map_format(o->format);
    LcmClient client(o->client);
    protocol::TileAssembler tiles;
    std::size_t drawn = 0;
    const auto result = client.download(o->session, tiles, [&](std::size_t have, std::size_t wanted) {
      if (o->quiet || (have != wanted && have < drawn + 8)) return;  // redraw every few segments
      drawn = have;
      draw_progress(have, wanted);
    });
    if (!o->quiet && drawn > 0) fmt::print(stderr, "\n");
    if (!result.ok) {
      fmt::print(stderr, "adit: error: download failed: {}\n", result.error);
      status = kExitFailure;
      return;
    }
    auto points = tiles.points();
    const bool moved = place_downloaded_points(points, result.frame);
    protocol::write_map(o->out, format, points);
    const auto& c = tiles.counts();
    const char* frame = !moved ? "the session's own frame"
                        : result.frame->source == frame_t::SOURCE_PRIOR_MAP ? "the prior map's frame"
                        : result.frame->source == frame_t::SOURCE_LEVEL     ? "the frame levelled by gravity"
                                                                            : "the map frame";
    fmt::print("{} points in {} tiles written to {} in {} ({} requests, {} duplicate and {} stale segments ignored)\n",
               points.size(), tiles.tile_count(), o->out, frame, result.requests, c.duplicate, c.stale);
    status = kExitOk;
  });
}

}  // namespace adit::tools
