// adit calibrate-wheels: fit wheel scales, effective track width and the
// encoder time offset against a reference trajectory (slam/wheel_calibration).

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "adit/eval/wheel_calibration.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

namespace can = adit::drivers::can;
namespace slam = adit::slam;

struct Options {
  std::string log;
  std::string dbc;
  std::string reference;
  std::string left = "WHEEL_SPEED_RL";
  std::string right = "WHEEL_SPEED_RR";
  std::string bus;
  double track_width = 1.6;
  double window = 1.0;
  double max_offset = 1.0;
  bool common_scale = false;
  bool no_time_offset = false;
};

std::vector<eval::WheelSpeedSample> read_wheels(const Options& o) {
  const can::Database db = can::load_dbc(o.dbc);
  const std::vector<std::string> wanted{o.left, o.right};
  can::SignalDecoder decoder(db.messages, wanted);
  if (decoder.signals()[0].message != decoder.signals().back().message)
    throw InputError(o.dbc, "--left/--right", "both wheel signals must be in the same message");
  for (const auto& s : decoder.signals())
    if (s.unit != "m/s") throw InputError(o.dbc, s.name, fmt::format("unit '{}' is not a speed convertible to m/s", s.unit));
  const int left = decoder.slot(o.left);
  const int right = decoder.slot(o.right);
  std::vector<double> v(decoder.slot_count());
  can::CandumpReader reader(o.log);
  std::vector<eval::WheelSpeedSample> samples;
  can::Frame f;
  while (reader.next(f)) {
    if (!o.bus.empty() && f.interface_name() != o.bus) continue;
    if (decoder.decode(f, v).status == can::DecodeStatus::decoded)
      samples.push_back({static_cast<double>(f.time_us) * 1e-6, v[static_cast<std::size_t>(left)], v[static_cast<std::size_t>(right)]});
  }
  for (const auto& e : reader.errors()) fmt::print(stderr, "warning: {}\n", reader.describe(e));
  if (decoder.stats().wrong_length > 0)
    fmt::print(stderr, "warning: {} wheel frames of the wrong length skipped\n", decoder.stats().wrong_length);
  return samples;
}

// CSV with a header naming t (or time), x (or east) and y (or north); '#' comments.
std::vector<eval::PlanarPosition> read_reference(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "--reference", "cannot open the reference trajectory");
  std::vector<eval::PlanarPosition> out;
  std::string line;
  std::size_t line_no = 0;
  int ct = -1, cx = -1, cy = -1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    if (ct < 0) {
      for (int i = 0; i < static_cast<int>(cells.size()); ++i) {
        const std::string& c = cells[static_cast<std::size_t>(i)];
        if (c == "t" || c == "time") ct = i;
        if (c == "x" || c == "east") cx = i;
        if (c == "y" || c == "north") cy = i;
      }
      if (ct < 0 || cx < 0 || cy < 0)
        throw InputError(fmt::format("{}:{}", file, line_no), "header", "expected columns t, x|east, y|north");
      continue;
    }
    const auto number = [&](int column) {
      try {
        std::size_t used = 0;
        const double v = std::stod(cells.at(static_cast<std::size_t>(column)), &used);
        return v;
      } catch (const std::exception&) {
        throw InputError(fmt::format("{}:{}", file, line_no), "value", "expected numbers in t, x and y");
      }
    };
    out.push_back({number(ct), number(cx), number(cy)});
    if (out.size() > 1 && !(out.back().t > out[out.size() - 2].t))
      throw InputError(fmt::format("{}:{}", file, line_no), "t", "times must increase");
  }
  return out;
}

int run(const Options& o) {
  const std::vector<eval::WheelSpeedSample> wheels = read_wheels(o);
  const std::vector<eval::PlanarPosition> reference = read_reference(o.reference);
  eval::CalibrationOptions c;
  c.nominal.track_width = o.track_width;
  c.window = o.window;
  c.max_time_offset = o.max_offset;
  c.separate_scales = !o.common_scale;
  c.fit_time_offset = !o.no_time_offset;
  eval::CalibrationResult r;
  try {
    r = eval::calibrate_wheels(wheels, reference, c);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.reference, "--reference", e.what());
  }
  const auto& sd = r.standard_deviation;
  fmt::print("wheel samples {}, reference poses {}, windows {} ({} iterations, {})\n", wheels.size(), reference.size(),
             r.windows, r.iterations, r.converged ? "converged" : "NOT converged");
  fmt::print("left scale       {:.5f} ± {:.5f}\n", r.left_scale, sd[0]);
  fmt::print("right scale      {:.5f} ± {:.5f}\n", r.right_scale, sd[1]);
  fmt::print("effective track  {:.3f} ± {:.3f} m (nominal {:.3f} m)\n", r.effective_track, sd[2], o.track_width);
  fmt::print("time offset      {:+.4f} ± {:.4f} s (reference = encoder + offset)\n", r.time_offset, sd[3]);
  fmt::print("residual rms     distance {:.3f} -> {:.3f} m, heading {:.5f} -> {:.5f} rad per {:.1f} s window\n",
             r.rms_distance_before, r.rms_distance_after, r.rms_heading_before, r.rms_heading_after, o.window);
  fmt::print("path length      reference {:.1f} m, wheels {:.1f} m before, {:.1f} m after\n", r.reference_length,
             r.wheel_length_before, r.wheel_length_after);
  fmt::print("endpoint error   {:.2f} m before, {:.2f} m after ({:.2f}% -> {:.2f}% of the path)\n",
             r.endpoint_error_before, r.endpoint_error_after, 100 * r.endpoint_error_before / r.reference_length,
             100 * r.endpoint_error_after / r.reference_length);
  return r.converged ? kExitOk : kExitFailure;
}

}  // namespace

void register_calibrate_wheels_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<Options>();
  CLI::App* c = app.add_subcommand("calibrate-wheels",
                                   "Fit wheel scales, effective track width and encoder time offset against a reference trajectory");
  c->add_option("--log", o->log, "candump -L log with the wheel speeds")->required();
  c->add_option("--dbc", o->dbc, "DBC file describing the wheel speed message")->required();
  c->add_option("--reference", o->reference, "Reference trajectory CSV with columns t, x|east, y|north (same clock)")->required();
  c->add_option("--left", o->left, "Left wheel speed signal (NAME or MESSAGE.NAME)")->capture_default_str();
  c->add_option("--right", o->right, "Right wheel speed signal (NAME or MESSAGE.NAME)")->capture_default_str();
  c->add_option("--bus", o->bus, "Only frames from this interface (e.g. can0)");
  c->add_option("--track-width", o->track_width, "Nominal track width between the two wheels, m")->capture_default_str();
  c->add_option("--window", o->window, "Residual window length, s")->capture_default_str()->check(CLI::PositiveNumber);
  c->add_option("--max-offset", o->max_offset, "Largest time offset searched, s")->capture_default_str()->check(CLI::NonNegativeNumber);
  c->add_flag("--common-scale", o->common_scale, "Fit one scale for both wheels instead of one each");
  c->add_flag("--no-time-offset", o->no_time_offset, "Do not fit the encoder-to-reference time offset");
  c->callback([o, &status] { status = run(*o); });
}

}  // namespace adit::tools
