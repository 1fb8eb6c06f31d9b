#include "autograv/map/workspace_fit.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "autograv/error.h"

namespace autograv {

namespace {

// Draws per reachable sample before giving up: a reachable set under 1/50 of the bounding cube
// means the bound or the reachability test is wrong.
constexpr int kMaxDrawsPerSample = 50;

std::vector<Eigen::Vector3d> sampleReachable(const ReachabilityTest& reachable,
                                             const Eigen::Vector3d& center_m, double radius_m,
                                             int samples, std::uint64_t seed) {
  if (!(radius_m > 0.0) || samples < 1) {
    throw Error("workspace fit: the bounding radius and the sample count must be positive");
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(samples));
  const long max_draws = static_cast<long>(samples) * kMaxDrawsPerSample;
  for (long draw = 0; draw < max_draws && static_cast<int>(points.size()) < samples; ++draw) {
    const Eigen::Vector3d point =
        center_m + radius_m * Eigen::Vector3d(unit(random), unit(random), unit(random));
    if (reachable(point)) points.push_back(point);
  }
  if (static_cast<int>(points.size()) < samples) {
    std::ostringstream message;
    message << "workspace fit: only " << points.size() << " of " << max_draws
            << " points drawn within " << radius_m * 1e3
            << " mm of the centre are reachable; check the workspace centre and radius";
    throw Error(message.str());
  }
  return points;
}

double fractionInside(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& low_m,
                      const Eigen::Vector3d& high_m) {
  const auto inside = std::count_if(points.begin(), points.end(), [&](const auto& p) {
    return (p.array() >= low_m.array()).all() && (p.array() <= high_m.array()).all();
  });
  return static_cast<double>(inside) / static_cast<double>(points.size());
}

}  // namespace

double workspaceCoverage(const WorkspaceGrid& grid, const ReachabilityTest& reachable,
                         const Eigen::Vector3d& center_m, double radius_m, int samples,
                         std::uint64_t seed) {
  const auto points = sampleReachable(reachable, center_m, radius_m, samples, seed);
  return fractionInside(points, grid.minCorner_m(), grid.maxCorner_m());
}

WorkspaceFit fitWorkspaceBox(const ReachabilityTest& reachable, const Eigen::Vector3d& center_m,
                             double radius_m, double target_coverage, int samples,
                             std::uint64_t seed) {
  if (!(target_coverage > 0.0 && target_coverage <= 1.0)) {
    throw Error("workspace fit: the target coverage must be in (0, 1]");
  }
  const auto points = sampleReachable(reachable, center_m, radius_m, samples, seed);
  const double aim = std::min(
      1.0, target_coverage + 3.0 * std::sqrt(target_coverage * (1.0 - target_coverage) / samples));

  // Sorted coordinates per axis, to read quantiles.
  std::vector<double> sorted[3];
  for (int axis = 0; axis < 3; ++axis) {
    sorted[axis].reserve(points.size());
    for (const auto& p : points) sorted[axis].push_back(p[axis]);
    std::sort(sorted[axis].begin(), sorted[axis].end());
  }
  const auto box_for = [&](double trim, Eigen::Vector3d& low, Eigen::Vector3d& high) {
    const auto last = static_cast<double>(points.size() - 1);
    for (int axis = 0; axis < 3; ++axis) {
      low[axis] = sorted[axis][static_cast<std::size_t>(std::floor(trim * last))];
      high[axis] = sorted[axis][static_cast<std::size_t>(std::ceil((1.0 - trim) * last))];
    }
  };
  // Coverage falls as the trimmed fraction grows: bisect for the largest trim that meets the aim.
  double keep = 0.0;  // meets the aim (trimming nothing holds every sample)
  double drop = 0.5;  // empty box
  Eigen::Vector3d low, high;
  for (int k = 0; k < 40; ++k) {
    const double trim = 0.5 * (keep + drop);
    box_for(trim, low, high);
    (fractionInside(points, low, high) >= aim ? keep : drop) = trim;
  }
  box_for(keep, low, high);
  WorkspaceFit fit;
  fit.center_m = 0.5 * (low + high);
  // Whole millimetres, rounded up: a box people can type and a grid that holds the fit.
  fit.size_m = ((high - low) * 1e3).array().ceil().matrix() * 1e-3;
  fit.size_m = fit.size_m.cwiseMax(Eigen::Vector3d::Constant(1e-3));
  const WorkspaceGrid box(fit.center_m, fit.size_m, Eigen::Vector3i::Constant(2));
  fit.workspace_coverage =
      workspaceCoverage(box, reachable, center_m, radius_m, samples, seed + 0x9e3779b97f4a7c15ULL);
  return fit;
}

}  // namespace autograv
