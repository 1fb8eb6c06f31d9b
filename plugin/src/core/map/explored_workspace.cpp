#include "autograv/map/explored_workspace.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
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
  if (directions_.size() > kMaxDirections) {
    throw Error("explored workspace: at most " + std::to_string(kMaxDirections) +
                " probe directions are supported, got " + std::to_string(directions_.size()));
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
  buildFacets();
}

namespace {

/// Closest point of the triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) noexcept {
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

/// A fixed, tiny, index-dependent nudge of a unit direction: directions that lie on one circle
/// (a cube's lattice) have many Delaunay triangulations, and the nudge picks one, the same one
/// every time.
Eigen::Vector3d nudged(const Eigen::Vector3d& u, std::size_t index) noexcept {
  std::uint64_t state = 0x9E3779B97F4A7C15ull * (index + 1);
  Eigen::Vector3d jitter;
  for (int k = 0; k < 3; ++k) {
    state ^= state >> 33;
    state *= 0xFF51AFD7ED558CCDull;
    state ^= state >> 33;
    jitter[k] = static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5;
  }
  return (u + 1e-7 * jitter).normalized();
}

/// Neighbours of each direction considered for its triangles, and the directions a candidate
/// triangle is checked against beyond a count of kExhaustiveCheckBelow.
constexpr std::size_t kTriangleNeighbours = 20;
constexpr std::size_t kEmptinessNeighbours = 40;
constexpr std::size_t kExhaustiveCheckBelow = 400;

}  // namespace

Eigen::Vector3d ExploredWorkspace::boundaryPoint_m(int index) const noexcept {
  const auto i = static_cast<std::size_t>(index);
  return center_m_ + radii_m_[i] * directions_[i];
}

void ExploredWorkspace::buildFacets() {
  // The spherical Delaunay triangulation of the directions: a triangle of three directions whose
  // plane has no other direction beyond it (the convex hull of the unit vectors). Candidates are
  // triangles among near neighbours; each is checked against every direction (or, for many
  // directions, against the nearest ones, which is where a violating direction would lie).
  const std::size_t n = directions_.size();
  std::vector<Eigen::Vector3d> unit(n);
  for (std::size_t i = 0; i < n; ++i) unit[i] = nudged(directions_[i], i);
  const std::size_t near_count = std::min(n - 1, kTriangleNeighbours);
  const std::size_t check_count = std::min(n - 1, kEmptinessNeighbours);
  std::vector<std::vector<int>> nearest(n);
  std::vector<int> order(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::iota(order.begin(), order.end(), 0);
    const std::size_t wanted = std::max(near_count, check_count) + 1;
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(wanted),
                      order.end(), [&](int a, int b) {
                        return unit[i].dot(unit[static_cast<std::size_t>(a)]) >
                               unit[i].dot(unit[static_cast<std::size_t>(b)]);
                      });
    for (std::size_t k = 0; k < wanted; ++k) {
      if (static_cast<std::size_t>(order[k]) != i) nearest[i].push_back(order[k]);
    }
  }
  std::vector<std::array<int, 3>> triangles;
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<int>& around = nearest[i];
    for (std::size_t j = 0; j < near_count; ++j) {
      for (std::size_t l = j + 1; l < near_count; ++l) {
        std::array<int, 3> corners = {static_cast<int>(i), around[j], around[l]};
        std::sort(corners.begin(), corners.end());
        if (corners[0] != static_cast<int>(i)) continue;  // found from its smallest index only
        const Eigen::Vector3d& a = unit[static_cast<std::size_t>(corners[0])];
        const Eigen::Vector3d& b = unit[static_cast<std::size_t>(corners[1])];
        const Eigen::Vector3d& c = unit[static_cast<std::size_t>(corners[2])];
        Eigen::Vector3d normal = (b - a).cross(c - a);
        const double area = normal.norm();
        if (!(area > 1e-14)) continue;
        normal /= area;
        const double offset = normal.dot(a);
        if (offset < 0.0) {
          normal = -normal;
          std::swap(corners[1], corners[2]);
        }
        const double level = normal.dot(a);
        const auto beyond = [&](int m) {
          return m != corners[0] && m != corners[1] && m != corners[2] &&
                 normal.dot(unit[static_cast<std::size_t>(m)]) > level + 1e-15;
        };
        bool empty = true;
        if (n < kExhaustiveCheckBelow) {
          for (std::size_t m = 0; m < n && empty; ++m) empty = !beyond(static_cast<int>(m));
        } else {
          for (std::size_t k = 0; k < check_count && empty; ++k) empty = !beyond(around[k]);
        }
        if (empty) triangles.push_back(corners);
      }
    }
  }
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
  facets_.clear();
  facets_.reserve(triangles.size());
  for (const std::array<int, 3>& corners : triangles) {
    Facet facet;
    facet.corners = corners;
    Eigen::Matrix3d spanned;
    spanned << directions_[static_cast<std::size_t>(corners[0])],
        directions_[static_cast<std::size_t>(corners[1])],
        directions_[static_cast<std::size_t>(corners[2])];
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(spanned);
    if (!lu.isInvertible()) continue;
    facet.to_weights = lu.inverse();
    const Eigen::Vector3d a = boundaryPoint_m(corners[0]) - center_m_;
    const Eigen::Vector3d b = boundaryPoint_m(corners[1]) - center_m_;
    const Eigen::Vector3d c = boundaryPoint_m(corners[2]) - center_m_;
    Eigen::Vector3d normal = (b - a).cross(c - a);
    const double area = normal.norm();
    if (!(area > 0.0)) continue;
    facet.normal = normal / area;
    facet.offset_m = facet.normal.dot(a);
    if (!(facet.offset_m > 0.0)) continue;  // the centre must lie inside every facet's plane
    facets_.push_back(facet);
  }
}

std::vector<std::array<int, 3>> ExploredWorkspace::facets() const {
  std::vector<std::array<int, 3>> corners;
  corners.reserve(facets_.size());
  for (const Facet& facet : facets_) corners.push_back(facet.corners);
  return corners;
}

double ExploredWorkspace::boundaryDistance_m(const Eigen::Vector3d& direction) const noexcept {
  if (directions_.empty()) return std::numeric_limits<double>::infinity();
  const double norm = direction.norm();
  if (!(norm > 0.0)) return minRadius_m();
  return exitDistance_m(direction / norm);
}

const ExploredWorkspace::Facet* ExploredWorkspace::facetHolding(
    const Eigen::Vector3d& u, Eigen::Vector3d& weights) const noexcept {
  constexpr double kWeightTolerance = -1e-12;
  for (const Facet& facet : facets_) {
    weights = facet.to_weights * u;
    if (weights.minCoeff() >= kWeightTolerance && facet.normal.dot(u) > 0.0) return &facet;
  }
  return nullptr;
}

bool ExploredWorkspace::enclosingFacet(const Eigen::Vector3d& u, std::array<int, 3>& corners,
                                       Eigen::Vector3d& weights) const noexcept {
  const Facet* facet = facetHolding(u, weights);
  if (facet == nullptr) return false;
  corners = facet->corners;
  weights = weights.cwiseMax(0.0);
  return true;
}

double ExploredWorkspace::exitDistance_m(const Eigen::Vector3d& u) const noexcept {
  // The facet whose cone holds u: the ray meets its triangle there. On a shared edge both
  // neighbours give the same point, so the boundary is continuous.
  Eigen::Vector3d weights;
  if (const Facet* facet = facetHolding(u, weights)) {
    return facet->offset_m / facet->normal.dot(u);
  }
  // No facet holds u (directions that leave part of the sphere uncovered, as all in one
  // hemisphere): nothing is known there but that the shortest reach was free.
  return minRadius_m();
}

double ExploredWorkspace::surfaceDistance_m(const Eigen::Vector3d& position_m) const noexcept {
  double nearest = std::numeric_limits<double>::infinity();
  for (const Facet& facet : facets_) {
    // Nothing of a triangle lies nearer than its plane.
    const double plane_m = std::abs(facet.offset_m - facet.normal.dot(position_m - center_m_));
    if (plane_m >= nearest) continue;
    const Eigen::Vector3d closest =
        closestOnTriangle(position_m, boundaryPoint_m(facet.corners[0]),
                          boundaryPoint_m(facet.corners[1]), boundaryPoint_m(facet.corners[2]));
    nearest = std::min(nearest, (closest - position_m).norm());
  }
  return nearest;
}

double ExploredWorkspace::depth_m(const Eigen::Vector3d& position_m) const noexcept {
  if (directions_.empty()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d offset = position_m - center_m_;
  const double distance = offset.norm();
  const bool inside = !(distance > 0.0) || distance <= exitDistance_m(offset / distance);
  const double surface_m = surfaceDistance_m(position_m);
  if (!std::isfinite(surface_m)) return inside ? minRadius_m() : -distance;
  return inside ? surface_m : -surface_m;
}

bool ExploredWorkspace::contains(const Eigen::Vector3d& position_m,
                                 double margin_m) const noexcept {
  if (directions_.empty()) return true;
  if (margin_m <= 0.0) {
    // On or inside the boundary is enough: the ray test alone, without the distance.
    const Eigen::Vector3d offset = position_m - center_m_;
    const double distance = offset.norm();
    if (!(distance > 0.0) || distance <= exitDistance_m(offset / distance)) return true;
    if (margin_m == 0.0) return false;
  }
  return depth_m(position_m) >= margin_m;
}

double ExploredWorkspace::clearanceAlong_m(const Eigen::Vector3d& position_m,
                                           const Eigen::Vector3d& direction, double limit_m,
                                           double resolution_m) const noexcept {
  if (directions_.empty()) return limit_m;
  if (!contains(position_m)) return 0.0;
  // Where the line leaves the model first: the nearest crossing of a triangle's plane, heading
  // outward, inside that triangle's cone. One pass over the triangles, as contains() takes.
  const Eigen::Vector3d offset = position_m - center_m_;
  double exit_m = limit_m;
  for (const Facet& facet : facets_) {
    const double approach = facet.normal.dot(direction);
    if (!(approach > 0.0)) continue;
    const double t_m = (facet.offset_m - facet.normal.dot(offset)) / approach;
    if (!(t_m >= 0.0) || t_m >= exit_m) continue;
    const Eigen::Vector3d weights = facet.to_weights * (offset + t_m * direction);
    if (weights.minCoeff() >= -1e-12) exit_m = t_m;
  }
  if (contains(position_m + std::max(0.0, exit_m - resolution_m) * direction)) return exit_m;
  // Directions no triangle covers (a model of one hemisphere): step along the line instead.
  double inside_m = 0.0;
  for (double s_m = resolution_m; s_m < exit_m; s_m += resolution_m) {
    if (!contains(position_m + s_m * direction)) break;
    inside_m = s_m;
  }
  return inside_m;
}

Eigen::Vector3d ExploredWorkspace::pullInside(const Eigen::Vector3d& position_m,
                                              double margin_m) const noexcept {
  if (contains(position_m, margin_m)) return position_m;
  const Eigen::Vector3d offset = position_m - center_m_;
  const double distance = offset.norm();
  if (!(distance > 0.0)) return center_m_;
  const Eigen::Vector3d u = offset / distance;
  double outer = std::min(distance, exitDistance_m(u));
  if (margin_m <= 0.0) return center_m_ + outer * u;
  if (depth_m(center_m_) < margin_m) return center_m_;
  // The outermost point of the ray that keeps the margin: depth falls toward the boundary, and
  // bisection to 0.1 nm keeps the pulled point a continuous function of the reach.
  double inner = 0.0;
  constexpr double kResolution_m = 1e-10;
  while (outer - inner > kResolution_m) {
    const double middle = 0.5 * (inner + outer);
    if (depth_m(center_m_ + middle * u) >= margin_m) {
      inner = middle;
    } else {
      outer = middle;
    }
  }
  return center_m_ + inner * u;
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
