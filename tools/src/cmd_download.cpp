// adit download: assembles a session's map from the payload's tiles over LCM,
// re-requesting whatever was lost, and writes it as PLY, PCD or LAS.

#include <memory>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/map_export.hpp"
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
};

void draw_progress(std::size_t have, std::size_t wanted) {
  constexpr int kWidth = 30;
  const double fraction = wanted == 0 ? 0.0 : static_cast<double>(have) / static_cast<double>(wanted);
  const int filled = static_cast<int>(fraction * kWidth);
  fmt::print(stderr, "\r[{}{}] {:3.0f}% {}/{} segments", std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(kWidth - filled), ' '), 100 * fraction, have, wanted);
}

}  // namespace

void register_download_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<DownloadOptions>();
  CLI::App* sub = app.add_subcommand("download", "Fetch a session's map from the payload and write it to a file");
  add_client_options(*sub, o->client);
  sub->add_option("--session", o->session, "Session id (default: the payload's current or last session)");
  sub->add_option("--format", o->format, "Output format: ply, pcd or las")
      ->required()
      ->check(CLI::IsMember({"ply", "pcd", "las"}));
  sub->add_option("--out", o->out, "Output file")->required();
  sub->add_flag("--quiet", o->quiet, "No progress bar");
  sub->callback([o, &status] {
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
    const auto points = tiles.points();
    protocol::write_map(o->out, format, points);
    const auto& c = tiles.counts();
    fmt::print("{} points in {} tiles written to {} ({} requests, {} duplicate and {} stale segments ignored)\n",
               points.size(), tiles.tile_count(), o->out, result.requests, c.duplicate, c.stale);
    status = kExitOk;
  });
}

}  // namespace adit::tools
