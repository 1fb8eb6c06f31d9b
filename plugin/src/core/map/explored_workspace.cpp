#include "autograv/map/explored_workspace.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "autograv/error.h"

namespace autograv {

ExploredWorkspace::ExploredWorkspace(const Eigen::Vector3d& center_m,
                                     std::vector<Eigen::Vector3d> directions,
                                     std::vector<double> radii_m)
    : center_m_(center_m), directions_(std::move(directions)), radii_m_(std::move(radii_m)) {
  if (!center_m_.allFinite()) throw Error("explored workspace: the centre is not finite");
  if (directions_.size() != radii_m_.size()) {
    std::ostringstream message;
    message << "explored workspace: " << directions_.size() << " directions but " << radii_m_.size()
            << " radii";
    throw Error(message.str());
  }
  if (directions_.size() < 6) {
    throw Error("explored workspace: at least 6 probe directions are needed, got " +
                std::to_string(directions_.size()));
  }
  for (std::size_t i = 0; i < directions_.size(); ++i) {
    const double norm = directions_[i].norm();
    if (!(std::isfinite(norm) && norm > 0.0)) {
      throw Error("explored workspace: direction " + std::to_string(i) + " is zero or not finite");
    }
    directions_[i] /= norm;
    if (!(std::isfinite(radii_m_[i]) && radii_m_[i] > 0.0)) {
      std::ostringstream message;
      message << "explored workspace: radius " << i << " must be a positive distance in m, got "
              << radii_m_[i];
      throw Error(message.str());
    }
  }
}

double ExploredWorkspace::boundaryDistance_m(const Eigen::Vector3d& direction) const noexcept {
  if (directions_.empty()) return std::numeric_limits<double>::infinity();
  const double norm = direction.norm();
  if (!(norm > 0.0)) return minRadius_m();
  return exitAlong(direction / norm).distance_m;
}

ExploredWorkspace::Exit ExploredWorkspace::exitAlong(const Eigen::Vector3d& u) const noexcept {
  // The kCandidates probe directions closest to u (largest dot products), closest first.
  constexpr int kCandidates = 6;
  int best[kCandidates];
  double best_dot[kCandidates];
  for (int k = 0; k < kCandidates; ++k) {
    best[k] = -1;
    best_dot[k] = -2.0;
  }
  for (int i = 0; i < static_cast<int>(directions_.size()); ++i) {
    const double dot = u.dot(directions_[static_cast<std::size_t>(i)]);
    for (int k = 0; k < kCandidates; ++k) {
      if (dot > best_dot[k]) {
        for (int m = kCandidates - 1; m > k; --m) {
          best[m] = best[m - 1];
          best_dot[m] = best_dot[m - 1];
        }
        best[k] = i;
        best_dot[k] = dot;
        break;
      }
    }
  }
  const auto point = [&](int i) {
    const auto index = static_cast<std::size_t>(i);
    return Eigen::Vector3d(radii_m_[index] * directions_[index]);
  };
  // The closest triple of boundary points whose cone holds u: the ray meets their triangle, a
  // chord of the workspace, so for a convex workspace the model stays inside what was reached.
  for (int a = 0; a < kCandidates; ++a) {
    for (int b = a + 1; b < kCandidates; ++b) {
      for (int c = b + 1; c < kCandidates; ++c) {
        if (best[c] < 0) continue;
        Eigen::Matrix3d corners;
        corners << point(best[a]), point(best[b]), point(best[c]);
        const Eigen::FullPivLU<Eigen::Matrix3d> lu(corners);
        if (!lu.isInvertible()) continue;
        // u = corners * w; the ray meets the triangle at u / sum(w) when every w >= 0.
        const Eigen::Vector3d w = lu.solve(u);
        if ((w.array() < -1e-12).any()) continue;
        const double sum = w.sum();
        if (!(sum > 0.0)) continue;
        const Eigen::Vector3d edge_b = corners.col(1) - corners.col(0);
        const Eigen::Vector3d edge_c = corners.col(2) - corners.col(0);
        const Eigen::Vector3d normal = edge_b.cross(edge_c);
        const double normal_norm = normal.norm();
        const double cosine = normal_norm > 0.0 ? std::abs(normal.dot(u)) / normal_norm : 1.0;
        return {1.0 / sum, std::max(cosine, kMinFacetCosine)};
      }
    }
  }
  // No triple holds u (directions too sparse around it): the nearest reach, at most.
  double reach = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3 && best[k] >= 0; ++k) {
    reach = std::min(reach, radii_m_[static_cast<std::size_t>(best[k])]);
  }
  return {reach, 1.0};
}

double ExploredWorkspace::depth_m(const Eigen::Vector3d& position_m) const noexcept {
  if (directions_.empty()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d offset = position_m - center_m_;
  const double distance = offset.norm();
  if (!(distance > 0.0)) return minRadius_m();
  // Along the ray the facet's plane is distance_m away; square to it, cosine times as far.
  const Exit exit = exitAlong(offset / distance);
  return (exit.distance_m - distance) * exit.cosine;
}

bool ExploredWorkspace::contains(const Eigen::Vector3d& position_m,
                                 double margin_m) const noexcept {
  if (directions_.empty()) return true;
  return depth_m(position_m) >= margin_m;
}

Eigen::Vector3d ExploredWorkspace::pullInside(const Eigen::Vector3d& position_m,
                                              double margin_m) const noexcept {
  if (contains(position_m, margin_m)) return position_m;
  const Eigen::Vector3d offset = position_m - center_m_;
  const double distance = offset.norm();
  if (!(distance > 0.0)) return center_m_;
  const Exit exit = exitAlong(offset / distance);
  const double reach = std::max(0.0, exit.distance_m - margin_m / exit.cosine);
  return center_m_ + offset * (reach / distance);
}

double ExploredWorkspace::minRadius_m() const noexcept {
  return radii_m_.empty() ? 0.0 : *std::min_element(radii_m_.begin(), radii_m_.end());
}

double ExploredWorkspace::maxRadius_m() const noexcept {
  return radii_m_.empty() ? 0.0 : *std::max_element(radii_m_.begin(), radii_m_.end());
}

std::vector<Eigen::Vector3d> ExploredWorkspace::probeDirections(int count) {
  if (count < 6) throw Error("explored workspace: at least 6 probe directions are needed");
  std::vector<Eigen::Vector3d> lattice;
  lattice.reserve(static_cast<std::size_t>(count));
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;  // from the top down
    const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
    lattice.emplace_back(ring * std::cos(golden_angle * i), ring * std::sin(golden_angle * i), z);
  }
  // Greedy nearest-neighbour path from the top, so that the probe moves little between rays.
  std::vector<Eigen::Vector3d> path;
  path.reserve(lattice.size());
  std::vector<bool> used(lattice.size(), false);
  std::size_t current = 0;
  for (int step = 0; step < count; ++step) {
    used[current] = true;
    path.push_back(lattice[current]);
    double best_dot = -2.0;
    std::size_t next = current;
    for (std::size_t j = 0; j < lattice.size(); ++j) {
      if (used[j]) continue;
      const double dot = lattice[current].dot(lattice[j]);
      if (dot > best_dot) {
        best_dot = dot;
        next = j;
      }
    }
    current = next;
  }
  return path;
}

}  // namespace autograv
