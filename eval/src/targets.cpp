#include "adit/eval/targets.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::eval {
namespace {

struct Matched {
  std::vector<std::string> ids;
  Eigen::Matrix3Xd truth;
  Eigen::Matrix3Xd map;
};

Matched match(const std::vector<Target>& truth, const std::vector<Target>& map, std::vector<std::string>& unmatched) {
  std::unordered_map<std::string, const Target*> by_id;
  for (const Target& t : map) by_id.emplace(t.id, &t);
  std::unordered_map<std::string, bool> in_truth;
  Matched m;
  std::vector<Eigen::Vector3d> a, b;
  for (const Target& t : truth) {
    in_truth.emplace(t.id, true);
    const auto it = by_id.find(t.id);
    if (it == by_id.end()) {
      unmatched.push_back(t.id);
      continue;
    }
    m.ids.push_back(t.id);
    a.push_back(t.position);
    b.push_back(it->second->position);
  }
  for (const Target& t : map)
    if (!in_truth.contains(t.id)) unmatched.push_back(t.id);
  m.truth.resize(3, static_cast<Eigen::Index>(a.size()));
  m.map.resize(3, static_cast<Eigen::Index>(b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    m.truth.col(static_cast<Eigen::Index>(i)) = a[i];
    m.map.col(static_cast<Eigen::Index>(i)) = b[i];
  }
  return m;
}

std::optional<Similarity> fit_on(const Matched& m, const std::vector<std::size_t>& cols, bool with_scale) {
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(cols.size()));
  Eigen::Matrix3Xd to(3, static_cast<Eigen::Index>(cols.size()));
  for (std::size_t k = 0; k < cols.size(); ++k) {
    from.col(static_cast<Eigen::Index>(k)) = m.map.col(static_cast<Eigen::Index>(cols[k]));
    to.col(static_cast<Eigen::Index>(k)) = m.truth.col(static_cast<Eigen::Index>(cols[k]));
  }
  return umeyama_fit(from, to, with_scale);
}

PointError residual(const Matched& m, std::size_t col, const Similarity& fit, bool control) {
  PointError e;
  e.id = m.ids[col];
  e.control = control;
  const auto c = static_cast<Eigen::Index>(col);
  e.delta = m.truth.col(c) - fit.apply(Eigen::Vector3d(m.map.col(c)));
  e.distance = e.delta.norm();
  return e;
}

std::vector<std::size_t> control_columns(const Matched& m, const std::vector<std::string>& control) {
  std::vector<std::size_t> cols;
  if (control.empty()) {
    for (std::size_t i = 0; i < m.ids.size(); ++i) cols.push_back(i);
  } else {
    for (const std::string& id : control) {
      const auto it = std::find(m.ids.begin(), m.ids.end(), id);
      if (it == m.ids.end())
        throw InputError("", "control", fmt::format("target '{}' is not in both the truth and the map file", id));
      const auto col = static_cast<std::size_t>(it - m.ids.begin());
      if (std::find(cols.begin(), cols.end(), col) != cols.end())
        throw InputError("", "control", fmt::format("target '{}' is listed twice", id));
      cols.push_back(col);
    }
  }
  if (cols.size() < 3)
    throw InputError("", "control", fmt::format("the fit needs at least 3 control targets, got {}", cols.size()));
  return cols;
}

}  // namespace

TargetReport evaluate_targets(const std::vector<Target>& truth, const std::vector<Target>& map,
                              const std::vector<std::string>& control, bool with_scale) {
  TargetReport report;
  const Matched m = match(truth, map, report.unmatched);
  const std::vector<std::size_t> cols = control_columns(m, control);

  // (a) consecutive distances, in the truth file's order.
  double sum_e2 = 0.0, sum_r2 = 0.0;
  for (Eigen::Index i = 1; i < m.truth.cols(); ++i) {
    DistanceError d;
    d.from = m.ids[static_cast<std::size_t>(i - 1)];
    d.to = m.ids[static_cast<std::size_t>(i)];
    d.true_distance = (m.truth.col(i) - m.truth.col(i - 1)).norm();
    d.map_distance = (m.map.col(i) - m.map.col(i - 1)).norm();
    d.error = d.true_distance - d.map_distance;
    d.rate = d.true_distance > 0.0 ? d.error / d.true_distance : 0.0;
    sum_e2 += d.error * d.error;
    sum_r2 += d.rate * d.rate;
    report.distances.push_back(d);
  }
  if (!report.distances.empty()) {
    report.distance_rmse = std::sqrt(sum_e2 / static_cast<double>(report.distances.size()));
    report.rate_rmse = std::sqrt(sum_r2 / static_cast<double>(report.distances.size()));
  }

  // (b) absolute residuals after the fit on the control targets.
  const auto fit = fit_on(m, cols, with_scale);
  if (!fit)
    throw InputError("", "control",
                     "the control targets lie on one line (or coincide): the rotation about it is not determined");
  report.fit = *fit;
  const auto is_control = [&](std::size_t col) { return std::find(cols.begin(), cols.end(), col) != cols.end(); };
  Eigen::Vector3d sum_xyz = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    report.points.push_back(residual(m, i, *fit, is_control(i)));
    sum_xyz += report.points.back().delta.cwiseAbs2();
  }
  const double n = static_cast<double>(report.points.size());
  report.rmse_xyz = (sum_xyz / n).cwiseSqrt();
  report.rmse_distance = std::sqrt(sum_xyz.sum() / n);

  // (c) leave-one-out: refit without the target (a check target is already out).
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    LeaveOneOut loo{m.ids[i], std::nullopt};
    if (!is_control(i)) {
      loo.error = report.points[i];
    } else {
      std::vector<std::size_t> rest;
      for (const std::size_t c : cols)
        if (c != i) rest.push_back(c);
      if (const auto refit = fit_on(m, rest, with_scale)) loo.error = residual(m, i, *refit, false);
    }
    report.leave_one_out.push_back(std::move(loo));
  }
  return report;
}

}  // namespace adit::eval
