// Control points (total-station CSV) and the georeferencing fit: column
// orders, units, duplicate and unknown ids, swapped columns, matching by
// geometry, and a control point shifted by 10 cm found by leaving it out.

#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/eval/control_points.hpp"
#include "adit/eval/georeference.hpp"

namespace adit::eval {
namespace {

ControlFile parse(const std::string& text, LengthUnit unit = LengthUnit::metre) {
  std::istringstream in(text);
  return read_control_points(in, "cp.csv", unit);
}

// The InputError's where() and reason() of parsing `text`, "" when it parses.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.where() + " | " + e.key() + " | " + e.reason();
  }
  return "";
}

TEST(ControlPoints, HeaderNamesTheColumnOrder) {
  const ControlFile plain = parse("CP1,500100.125,7000200.250,312.5\n");
  ASSERT_EQ(plain.points.size(), 1u);
  EXPECT_EQ(plain.header_line, 0u);
  EXPECT_DOUBLE_EQ(plain.points[0].enh.x(), 500100.125);
  EXPECT_DOUBLE_EQ(plain.points[0].enh.y(), 7000200.250);
  const ControlFile swapped = parse("# from the total station\nPoint,Northing,Easting,Elevation\nCP1,7000200.250,500100.125,312.5\n");
  EXPECT_EQ(swapped.header_line, 2u);
  EXPECT_EQ(swapped.points[0].line, 3u);
  EXPECT_DOUBLE_EQ(swapped.points[0].enh.x(), 500100.125);
  EXPECT_DOUBLE_EQ(swapped.points[0].enh.y(), 7000200.250);
  EXPECT_DOUBLE_EQ(swapped.points[0].enh.z(), 312.5);
}

TEST(ControlPoints, FeetAreConvertedWhenStated) {
  const ControlFile ft = parse("id,E,N,H\nA,1000,2000,10\n", LengthUnit::foot);
  EXPECT_DOUBLE_EQ(ft.points[0].enh.x(), 304.8);
  const ControlFile us = parse("id,E,N,H\nA,3937,0,0\n", LengthUnit::us_survey_foot);
  EXPECT_NEAR(us.points[0].enh.x(), 1200.0, 1e-9);
  EXPECT_FALSE(parse_length_unit("yards"));
}

TEST(ControlPoints, BadLinesNameFileAndLine) {
  EXPECT_EQ(error_of([] { parse("id,E,N,H\nA,1,2,3\nB,4,5,6\nA,7,8,9\n"); }),
            "cp.csv:4 | id | 'A' appears twice (also line 2)");
  EXPECT_EQ(error_of([] { parse("id,E,N,H\nA,1,2\n"); }), "cp.csv:2 |  | expected 4 fields (id,E,N,H), found 3");
  EXPECT_EQ(error_of([] { parse("A,1,2,3\nB,4,x5,6\n"); }), "cp.csv:2 | N | 'x5' is not a finite number");
  EXPECT_EQ(error_of([] { parse("id,E,E,H\n"); }), "cp.csv:1 | header | 'E' names column E twice");
  EXPECT_EQ(error_of([] { parse("id,E,N,depth\n"); }),
            "cp.csv:1 | header | 'depth' is not a column name (id, E|easting, N|northing, H|height)");
  EXPECT_EQ(error_of([] { parse("# nothing\n"); }), "cp.csv |  | no control points");
}

// A site grid far from the origin, turned 37° and raised: map -> site.
Similarity site_transform() {
  Similarity s;
  s.rotation = Eigen::AngleAxisd(37.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
               Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitX()).toRotationMatrix();
  s.translation = {512345.678, 7012345.432, 1234.5};
  return s;
}

// Eight targets on the walls of a bent 80 m drift, in the map frame.
std::vector<Target> map_targets() {
  return {{"1", {3.0, 2.1, 1.2}},   {"2", {14.0, -2.0, 1.6}}, {"3", {27.0, 2.2, 0.9}},  {"4", {38.5, -1.9, 1.4}},
          {"5", {44.0, 9.0, 1.1}},  {"6", {47.8, 22.0, 1.7}}, {"7", {43.9, 35.0, 1.3}}, {"8", {48.1, 47.0, 1.5}}};
}

// Control points CP<k> for the given map targets through the site transform,
// with `noise` (m, uniform) and `shift` added to one of them.
std::string control_csv(const std::vector<int>& which, double noise, int shifted = -1,
                        const Eigen::Vector3d& shift = Eigen::Vector3d::Zero(), bool swap_en = false) {
  const auto targets = map_targets();
  const Similarity s = site_transform();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-noise, noise);
  std::string csv;
  for (const int k : which) {
    Eigen::Vector3d p = s.apply(targets[static_cast<std::size_t>(k - 1)].position) + Eigen::Vector3d(u(rng), u(rng), u(rng));
    if (k == shifted) p += shift;
    if (swap_en) std::swap(p.x(), p.y());
    csv += fmt::format("CP{},{:.4f},{:.4f},{:.4f}\n", k, p.x(), p.y(), p.z());
  }
  return csv;
}

TEST(Georeference, GeometryMatchesRenamedTargetsAndFitsSiteCoordinates) {
  const ControlFile control = parse(control_csv({1, 3, 5, 8}, 0.003));
  const Georeference g = georeference(control, map_targets(), {});
  EXPECT_EQ(g.matched_by, "geometry");
  ASSERT_EQ(g.points.size(), 4u);
  EXPECT_EQ(g.points[0].target_id, "1");
  EXPECT_EQ(g.points[1].target_id, "3");
  EXPECT_EQ(g.points[2].target_id, "5");
  EXPECT_EQ(g.points[3].target_id, "8");
  EXPECT_LT(g.rms_m, 0.006);
  for (const ControlResidual& r : g.points) {
    EXPECT_TRUE(r.in_fit);
    EXPECT_FALSE(r.flagged) << r.id;
  }
  // The targets not used land where the site transform puts them (mm, at E 500 000).
  for (const int k : {2, 4, 6, 7}) {
    const Eigen::Vector3d m = map_targets()[static_cast<std::size_t>(k - 1)].position;
    EXPECT_LT((g.fit.apply(m) - site_transform().apply(m)).norm(), 0.006) << k;
  }
}

TEST(Georeference, LevelFitTurnsAboutTheVerticalOnly) {
  // A map whose heights drift (+2 cm per 10 m along x): the full fit tilts the
  // map to follow the control points, the level fit only shifts it in H.
  std::vector<Target> drifted = map_targets();
  for (Target& t : drifted) t.position.z() += 0.002 * t.position.x();
  Similarity level_site = site_transform();
  level_site.rotation = Eigen::AngleAxisd(37.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::string csv;
  for (const int k : {1, 3, 5, 8}) {
    const Eigen::Vector3d p = level_site.apply(map_targets()[static_cast<std::size_t>(k - 1)].position);
    csv += fmt::format("CP{},{:.4f},{:.4f},{:.4f}\n", k, p.x(), p.y(), p.z());
  }
  GeorefOptions level;
  level.level = true;
  const Georeference g = georeference(parse(csv), drifted, level);
  EXPECT_NEAR(g.fit.rotation(2, 2), 1.0, 1e-12);
  const Eigen::Matrix3d r = g.fit.rotation;
  EXPECT_NEAR(std::atan2(r(1, 0), r(0, 0)) * 180.0 / std::numbers::pi, 37.0, 0.01);
  // Plan positions exact; heights off by the drift about its mean over the control points.
  for (const ControlResidual& p : g.points) EXPECT_LT(p.delta.head<2>().norm(), 1e-3) << p.id;
  const Georeference full = georeference(parse(csv), drifted, {});
  EXPECT_GT(std::acos(full.fit.rotation(2, 2)), 0.001);  // the full fit tilts
}

TEST(Georeference, MatchesByIdWhenEveryIdIsATarget) {
  std::vector<Target> targets = map_targets();
  for (Target& t : targets) t.id = "CP" + t.id;
  const Georeference g = georeference(parse(control_csv({2, 4, 6, 7}, 0.0)), targets, {});
  EXPECT_EQ(g.matched_by, "id");
  EXPECT_LT(g.rms_m, 1e-4);
  // Some ids known and some not: the unknown one is named with its line.
  EXPECT_EQ(error_of([&] { georeference(parse(control_csv({2, 4}, 0.0) + "CPX,1,2,3\n" + control_csv({7}, 0.0)), targets, {}); }),
            "cp.csv:3 | id | 'CPX' is not a target id (3 of 4 control ids are; --match geometry ignores ids)");
}

TEST(Georeference, LeaveOneOutFlagsAControlPointShiftedTenCentimetres) {
  // Shifted 10 cm horizontally: a plain fit on all four spreads it (each
  // residual a few cm, the shifted one's under the 10 cm); leaving it out shows it whole.
  for (const int shifted : {1, 3, 5, 8}) {
    const ControlFile control = parse(control_csv({1, 3, 5, 8}, 0.003, shifted, {0.06, 0.08, 0.0}));
    const Georeference g = georeference(control, map_targets(), {});
    for (const ControlResidual& r : g.points) {
      const bool is_shifted = r.id == fmt::format("CP{}", shifted);
      EXPECT_EQ(r.flagged, is_shifted) << "shifted CP" << shifted << ", " << r.id << " residual " << r.distance;
      EXPECT_EQ(r.in_fit, !is_shifted) << "shifted CP" << shifted << ", " << r.id;
      if (is_shifted) {
        EXPECT_NEAR(r.distance, 0.10, 0.01);
      }
    }
    EXPECT_LT(g.rms_m, 0.006);
  }
}

TEST(Georeference, PlainFitWouldSpreadTheBlunder) {
  // The reason for the check column: with the shifted point in, no residual reaches 10 cm.
  const ControlFile control = parse(control_csv({1, 3, 5, 8}, 0.0, 5, {0.06, 0.08, 0.0}));
  GeorefOptions loose;
  loose.tolerance_m = 0.2;  // nothing left out
  const Georeference g = georeference(control, map_targets(), loose);
  double largest = 0.0;
  for (const ControlResidual& r : g.points) largest = std::max(largest, r.distance);
  EXPECT_LT(largest, 0.09);
  EXPECT_GT(g.points[2].loo_delta->norm(), 0.09);
}

TEST(Georeference, BadControlFilesAreRefusedWithFileAndLine) {
  const auto targets = map_targets();
  // E and N exchanged without a header: only the mirrored fit works.
  EXPECT_NE(error_of([&] { georeference(parse(control_csv({1, 3, 5, 8}, 0.003, -1, Eigen::Vector3d::Zero(), true)), targets, {}); })
                .find("cp.csv:1 | E,N | E and N look swapped"),
            std::string::npos);
  // ... and with a header that says E,N.
  EXPECT_NE(error_of([&] { georeference(parse("id,E,N,H\n" + control_csv({1, 3, 5, 8}, 0.003, -1, Eigen::Vector3d::Zero(), true)), targets, {}); })
                .find("cp.csv:1 | E,N | E and N look swapped: the fit leaves a median residual"),
            std::string::npos);
  // Feet read as metres.
  std::string feet;
  for (const ControlPoint& p : parse(control_csv({1, 3, 5, 8}, 0.003)).points)
    feet += fmt::format("{},{:.4f},{:.4f},{:.4f}\n", p.id, p.enh.x() / 0.3048, p.enh.y() / 0.3048, p.enh.z() / 0.3048);
  const std::string e = error_of([&] { georeference(parse(feet), targets, {}); });
  EXPECT_NE(e.find("cp.csv | units | the control points lie 3.28"), std::string::npos) << e;
  EXPECT_NE(e.find("looks to be in feet"), std::string::npos) << e;
  const Georeference in_feet = georeference(parse(feet, LengthUnit::foot), targets, {});
  EXPECT_LT(in_feet.rms_m, 0.006);
  // Fewer than three matches.
  EXPECT_EQ(error_of([&] { georeference(parse(control_csv({1, 8}, 0.0)), targets, {}); }),
            "cp.csv |  | 2 control points matched a target by geometry: CP1 (line 1), CP8 (line 2); the fit needs at least 3");
  // Points of another site entirely.
  EXPECT_NE(error_of([&] { georeference(parse("A,0,0,0\nB,5,0,0\nC,0,7,0\nD,9,9,9\n"), targets, {}); }).find("cp.csv |  |"),
            std::string::npos);
}

TEST(Georeference, GeometryMatchingIgnoresExtraTargetsAndControls) {
  // A control point whose target was not found: left unmatched, not forced.
  std::vector<Target> found = map_targets();
  found.erase(found.begin() + 4);  // target 5 not found
  const Georeference g = georeference(parse(control_csv({1, 3, 5, 8}, 0.003)), found, {});
  ASSERT_EQ(g.points.size(), 3u);
  ASSERT_EQ(g.unmatched.size(), 1u);
  EXPECT_EQ(g.unmatched[0], "CP5");
}

}  // namespace
}  // namespace adit::eval
