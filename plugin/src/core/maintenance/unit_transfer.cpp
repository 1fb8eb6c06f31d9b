#include "autograv/maintenance/unit_transfer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>

#include <Eigen/Dense>

#include "autograv/device/device_specifications.h"
#include "autograv/device/servo_sample.h"
#include "autograv/error.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/field_fit.h"
#include "autograv/map/measurement_plan.h"

namespace autograv {

namespace {

// A more flexible correction must predict the fit points this much better (mean leave-one-out,
// relative) than a simpler one to be kept: as the field model's choice (kFieldModelMargin).
constexpr double kCorrectionMargin = 0.05;
// Fewest fit points a correction is chosen from: the affine one has twelve unknowns, and its
// leave-one-out needs a few points more than that over three components.
constexpr std::size_t kMinFitPoints = 8;

// A value measured where it stands (at its vertex, or at its point inside the stops).
bool isMeasured(const VertexEstimate& vertex) noexcept {
  return vertex.outcome == VertexOutcome::kConverged;
}

double curlWeightOf(CorrectionModel model) noexcept {
  return model == CorrectionModel::kComponentwise ? 1.0 : 0.0;
}

bool isFieldModel(CorrectionModel model) noexcept {
  return model == CorrectionModel::kConservative || model == CorrectionModel::kComponentwise;
}

bool parseCorrectionModel(const std::string& name, CorrectionModel& model) noexcept {
  for (CorrectionModel candidate :
       {CorrectionModel::kShift, CorrectionModel::kAffine, CorrectionModel::kConservative,
        CorrectionModel::kComponentwise}) {
    if (name == toString(candidate)) {
      model = candidate;
      return true;
    }
  }
  return false;
}

// Mean and largest of |residual_i| / |value_i|.
CorrectionScore scoreOf(CorrectionModel model, const std::vector<Eigen::Vector3d>& residuals_n,
                        const std::vector<Eigen::Vector3d>& values_n) {
  CorrectionScore score;
  score.model = model;
  for (std::size_t i = 0; i < residuals_n.size(); ++i) {
    const double rel = residuals_n[i].norm() / std::max(values_n[i].norm(), 1e-9);
    score.mean_rel += rel;
    score.max_rel = std::max(score.max_rel, rel);
  }
  score.mean_rel /= static_cast<double>(std::max<std::size_t>(1, residuals_n.size()));
  return score;
}

// The affine correction d = W^T [g; 1] of the differences `d` against the prior's values `g`, by
// least squares; false when the values do not determine it. With `loo`, each point's
// leave-one-out residual (PRESS: its residual over 1 - its leverage).
bool fitAffine(const std::vector<Eigen::Vector3d>& prior_n,
               const std::vector<Eigen::Vector3d>& differences_n, Eigen::Matrix<double, 4, 3>& w,
               std::vector<Eigen::Vector3d>* loo) {
  const auto n = static_cast<Eigen::Index>(prior_n.size());
  if (n < 6) return false;
  Eigen::MatrixXd x(n, 4);
  Eigen::MatrixXd y(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    x.row(i) << prior_n[static_cast<std::size_t>(i)].transpose(), 1.0;
    y.row(i) = differences_n[static_cast<std::size_t>(i)].transpose();
  }
  const Eigen::Matrix4d normal = x.transpose() * x;
  const Eigen::LDLT<Eigen::Matrix4d> solver(normal);
  if (solver.info() != Eigen::Success || !(solver.rcond() > 1e-12)) return false;
  w = solver.solve(x.transpose() * y);
  if (!w.allFinite()) return false;
  if (loo != nullptr) {
    loo->clear();
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector4d xi = x.row(i).transpose();
      const double leverage = xi.dot(solver.solve(xi));
      if (!(leverage < 1.0 - 1e-9)) return false;
      const Eigen::Vector3d residual = y.row(i).transpose() - w.transpose() * xi;
      loo->push_back(residual / (1.0 - leverage));
    }
  }
  return true;
}

// The correction at `position_m` where the prior's value is `prior_n`.
class Correction {
 public:
  explicit Correction(const MapPrior& prior) : gain_(prior.gain), offset_n_(prior.offset_n) {
    CorrectionModel model = CorrectionModel::kShift;
    if (!parseCorrectionModel(prior.correction_model, model)) {
      throw Error("map prior: unknown correction model '" + prior.correction_model + "'");
    }
    if (isFieldModel(model) && !prior.residuals_n.empty()) {
      fit_.emplace(prior.points_m, prior.residuals_n, curlWeightOf(model));
    }
  }
  Eigen::Vector3d at(const Eigen::Vector3d& position_m, const Eigen::Vector3d& prior_n) const {
    Eigen::Vector3d change_n = (gain_ - Eigen::Matrix3d::Identity()) * prior_n + offset_n_;
    if (fit_) change_n += fit_->at(position_m);
    return change_n;
  }

 private:
  Eigen::Matrix3d gain_;
  Eigen::Vector3d offset_n_;
  std::optional<FieldFit> fit_;
};

std::string millimetres(double metres) {
  std::ostringstream text;
  text.precision(1);
  text << std::fixed << metres * 1e3 << " mm";
  return text.str();
}

std::string percent(double fraction) {
  std::ostringstream text;
  text.precision(2);
  text << std::fixed << fraction * 100.0 << " %";
  return text.str();
}

// `count` of the directions `workspace` was explored in, nearest to the axes' directions first
// (+z, +x, +y, -x, -y, -z: a short probe path), then spread farthest first.
std::vector<Eigen::Vector3d> checkDirections(const ExploredWorkspace& workspace, int count) {
  const std::vector<Eigen::Vector3d>& all = workspace.directions();
  std::vector<bool> taken(all.size(), false);
  std::vector<Eigen::Vector3d> chosen;
  const auto take = [&](std::size_t index) {
    taken[index] = true;
    chosen.push_back(all[index]);
  };
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitZ(),  Eigen::Vector3d::UnitX(),
                                  Eigen::Vector3d::UnitY(),  -Eigen::Vector3d::UnitX(),
                                  -Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ()};
  for (const Eigen::Vector3d& axis : axes) {
    if (static_cast<int>(chosen.size()) >= count) break;
    std::size_t best = all.size();
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (!taken[i] && (best == all.size() || all[i].dot(axis) > all[best].dot(axis))) best = i;
    }
    if (best < all.size()) take(best);
  }
  while (static_cast<int>(chosen.size()) < std::min<int>(count, static_cast<int>(all.size()))) {
    std::size_t farthest = all.size();
    double farthest_dot = 2.0;
    for (std::size_t i = 0; i < all.size(); ++i) {
      if (taken[i]) continue;
      double nearest = -2.0;
      for (const Eigen::Vector3d& u : chosen) nearest = std::max(nearest, all[i].dot(u));
      if (nearest < farthest_dot) {
        farthest_dot = nearest;
        farthest = i;
      }
    }
    take(farthest);
  }
  return chosen;
}

// The candidates fitted to the fit points of `measured` (those not kept to check), and the one
// kept: the simplest unless a more flexible one predicts the points better by kCorrectionMargin.
struct Fit {
  bool ok = false;  // enough points to fit and score
  std::vector<CorrectionScore> scores;
  CorrectionScore chosen;
  MapPrior correction;  // correction_model, gain, offset_n, points_m, residuals_n
};

Fit fitCorrection(const TransferResult& measured) {
  Fit fit;
  std::vector<Eigen::Vector3d> points_m, prior_n, measured_n, differences_n;
  for (std::size_t k = 0; k < measured.points_m.size(); ++k) {
    if (measured.is_check[k]) continue;
    points_m.push_back(measured.points_m[k]);
    prior_n.push_back(measured.prior_n[k]);
    measured_n.push_back(measured.measured_n[k]);
    differences_n.push_back(measured.measured_n[k] - measured.prior_n[k]);
  }
  if (points_m.size() < kMinFitPoints) return fit;
  std::vector<Eigen::Vector3d> loo;
  Eigen::Vector3d mean_n = Eigen::Vector3d::Zero();
  for (const auto& d : differences_n) mean_n += d;
  mean_n /= static_cast<double>(differences_n.size());
  const double inflation =
      static_cast<double>(differences_n.size()) / static_cast<double>(differences_n.size() - 1);
  for (const auto& d : differences_n) loo.push_back((d - mean_n) * inflation);
  fit.scores.push_back(scoreOf(CorrectionModel::kShift, loo, measured_n));
  Eigen::Matrix<double, 4, 3> affine = Eigen::Matrix<double, 4, 3>::Zero();
  if (fitAffine(prior_n, differences_n, affine, &loo)) {
    fit.scores.push_back(scoreOf(CorrectionModel::kAffine, loo, measured_n));
  }
  for (CorrectionModel model : {CorrectionModel::kConservative, CorrectionModel::kComponentwise}) {
    try {
      loo = leaveOneOutResiduals_n(points_m, differences_n, curlWeightOf(model));
      fit.scores.push_back(scoreOf(model, loo, measured_n));
    } catch (const Error&) {
      // Points that do not determine this fit: the candidate is not scored.
    }
  }
  fit.chosen = fit.scores.front();
  for (const CorrectionScore& score : fit.scores) {
    if (score.mean_rel < (1.0 - kCorrectionMargin) * fit.chosen.mean_rel) fit.chosen = score;
  }
  MapPrior& correction = fit.correction;
  correction.correction_model = toString(fit.chosen.model);
  correction.points_m = points_m;
  switch (fit.chosen.model) {
    case CorrectionModel::kShift:
      correction.offset_n = mean_n;
      break;
    case CorrectionModel::kAffine:
      correction.gain = Eigen::Matrix3d::Identity() + affine.topRows<3>().transpose();
      correction.offset_n = affine.row(3).transpose();
      break;
    case CorrectionModel::kConservative:
    case CorrectionModel::kComponentwise:
      correction.residuals_n = differences_n;
      break;
  }
  fit.ok = true;
  return fit;
}

// The MAD of normally scattered values times this is their standard deviation.
constexpr double kMadToSigma = 1.4826;

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle),
                   values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(),
                                          values.begin() + static_cast<std::ptrdiff_t>(middle)));
}

}  // namespace

std::vector<bool> standingOut(const std::vector<double>& errors_rel, double mads, double min_rel) {
  std::vector<bool> out(errors_rel.size(), false);
  if (errors_rel.size() < 3) {
    // Fewer than two others: nothing to judge a point against, so every point stands out.
    std::fill(out.begin(), out.end(), true);
    return out;
  }
  std::vector<double> others;
  for (std::size_t i = 0; i < errors_rel.size(); ++i) {
    others.clear();
    for (std::size_t j = 0; j < errors_rel.size(); ++j) {
      if (j != i) others.push_back(errors_rel[j]);
    }
    const double centre = median(others);
    for (double& value : others) value = std::abs(value - centre);
    const double spread = kMadToSigma * median(others);
    // At least twice what the others show, too: a point 9.3 % off among others 8.6-9.2 % off
    // is as far off as they are, not an outlier among them.
    out[i] = errors_rel[i] - centre > std::max({mads * spread, min_rel, centre});
  }
  return out;
}

namespace {

// `indices` in a short path from `from_m` (nearest next point first): the spread points lie far
// apart, and the moves between them cost as much device time as the holds.
std::vector<int> shortTour(std::vector<int> indices, const std::vector<Eigen::Vector3d>& points_m,
                           Eigen::Vector3d from_m) {
  std::vector<int> tour;
  while (!indices.empty()) {
    const auto next = std::min_element(indices.begin(), indices.end(), [&](int a, int b) {
      return (points_m[static_cast<std::size_t>(a)] - from_m).squaredNorm() <
             (points_m[static_cast<std::size_t>(b)] - from_m).squaredNorm();
    });
    tour.push_back(*next);
    from_m = points_m[static_cast<std::size_t>(*next)];
    indices.erase(next);
  }
  return tour;
}

}  // namespace

const char* toString(CorrectionModel model) noexcept {
  switch (model) {
    case CorrectionModel::kShift:
      return "shift";
    case CorrectionModel::kAffine:
      return "affine";
    case CorrectionModel::kConservative:
      return "conservative";
    case CorrectionModel::kComponentwise:
      return "componentwise";
  }
  return "unknown";
}

void checkTransferPrior(const GravityMap& prior, const std::string& device_model,
                        const TransferOptions& options) {
  const MapMetadata& metadata = prior.metadata();
  if (metadata.device_model != device_model) {
    throw Error("the map given as the prior is of a '" + metadata.device_model +
                "', this device is a '" + device_model +
                "': a map of another model cannot be corrected to this one; run a whole "
                "calibration (autograv calibrate or wizard without --like)");
  }
  if (metadata.workspace.empty()) {
    throw Error(
        "the map given as the prior has no explored workspace (made before the "
        "exploration existed, or without it): its unit's reach cannot be checked; run a "
        "whole calibration");
  }
  if (options.first_points < 10 || options.batch_points < 1 ||
      options.max_points < options.first_points || options.check_every < 2 ||
      options.probe_directions < 6 || !(options.time_budget_s > 0.0) ||
      !(options.enough_rel >= 0.0) || !(options.stand_out_mads >= 0.0) ||
      !(options.stand_out_min_rel >= 0.0)) {
    throw Error(
        "transfer: TransferOptions needs first_points >= 10, batch_points >= 1, "
        "max_points >= first_points, check_every >= 2, probe_directions >= 6, a positive "
        "time budget and a non-negative enough_rel, stand_out_mads and stand_out_min_rel");
  }
  const auto measured =
      std::count_if(prior.vertices().begin(), prior.vertices().end(),
                    [](const VertexEstimate& vertex) { return isMeasured(vertex); });
  if (measured < options.first_points) {
    throw Error("the map given as the prior has " + std::to_string(measured) +
                " measured points, fewer than the " + std::to_string(options.first_points) +
                " the correction measures at first; run a whole calibration");
  }
}

std::vector<int> spreadMeasuredVertices(const GravityMap& prior, int count) {
  const WorkspaceGrid& grid = prior.grid();
  std::vector<int> candidates;
  std::vector<Eigen::Vector3d> points_m;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = prior.vertices()[static_cast<std::size_t>(i)];
    if (!isMeasured(vertex)) continue;
    candidates.push_back(i);
    points_m.push_back(vertex.measuredAt_m(grid.vertexPosition(i)));
  }
  std::vector<int> chosen;
  if (candidates.empty() || count <= 0) return chosen;
  const Eigen::Vector3d center_m =
      prior.metadata().workspace.empty() ? grid.center_m() : prior.metadata().workspace.center_m();
  std::size_t next = 0;
  for (std::size_t i = 1; i < points_m.size(); ++i) {
    if ((points_m[i] - center_m).norm() < (points_m[next] - center_m).norm()) next = i;
  }
  std::vector<double> distance_m(points_m.size(), std::numeric_limits<double>::infinity());
  while (static_cast<int>(chosen.size()) <
         std::min<int>(count, static_cast<int>(points_m.size()))) {
    chosen.push_back(candidates[next]);
    for (std::size_t i = 0; i < points_m.size(); ++i) {
      distance_m[i] = std::min(distance_m[i], (points_m[i] - points_m[next]).norm());
    }
    next = static_cast<std::size_t>(std::max_element(distance_m.begin(), distance_m.end()) -
                                    distance_m.begin());
  }
  return chosen;
}

GravityMap correctedMap(const GravityMap& prior, const MapPrior& correction, MapMetadata metadata) {
  const Correction change(correction);
  std::vector<VertexEstimate> vertices = prior.vertices();
  for (int i = 0; i < prior.grid().vertexCount(); ++i) {
    VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    // Each value corrected where it stands, from itself: a measured value keeps what the prior's
    // unit measured there.
    vertex.gravity_n += change.at(prior.grid().vertexPosition(i), vertex.gravity_n);
    if (vertex.measuredOffVertex()) {
      vertex.measured_gravity_n += change.at(vertex.measured_at_m, vertex.measured_gravity_n);
    }
  }
  metadata.prior = correction;
  return GravityMap(prior.grid(), std::move(vertices), std::move(metadata));
}

TransferResult transferMap(HapticDevice& device, TickSource& ticks, const GravityMap& prior,
                           const TransferOptions& options) {
  const DeviceSpecifications& specs = device.specifications();
  checkTransferPrior(prior, specs.model_name, options);
  const EstimationParameters& parameters = options.parameters;
  const double period_s = parameters.servo_period_s;
  const double continuous_n = continuousForceRating_n(specs);
  const ExploredWorkspace& prior_workspace = prior.metadata().workspace;
  TransferResult result;
  result.prior.source = options.prior_source;
  result.prior.device_serial = prior.metadata().device_serial;
  result.prior.created_utc = prior.metadata().created_utc;

  const ServoSample first = readServoSample(device);
  if (!first.valid) {
    throw Error("transfer: the device '" + specs.model_name +
                "' gives no valid position (is it open and homed?)");
  }
  const long max_ticks = static_cast<long>(std::ceil(options.timeout_s / period_s));
  long tick = 0;
  double servo_s = 0.0;  // the ticks' own intervals: a late tick is time the device spent
  double next_progress_s = 0.0;
  // One servo tick of `law` (the explorer's or the calibrator's step), its force accounted
  // against the device's ratings. False when the loop must end (no tick, or the time is up).
  const auto servo = [&](auto&& law) {
    if (tick >= max_ticks || !ticks.waitForNextTick()) return false;
    ++tick;
    const ServoSample sample = readServoSample(device, ticks.lastInterval_s());
    const double interval_s = sample.interval_s > 0.0 ? sample.interval_s : period_s;
    servo_s += interval_s;
    Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
    law(sample, force_n);
    device.setForce(force_n);
    result.peak_force_n = std::max(result.peak_force_n, force_n.norm());
    if (force_n.norm() > continuous_n) result.seconds_above_continuous_force += interval_s;
    return true;
  };
  const auto elapsed_s = [&] { return servo_s; };
  const auto report = [&](TransferProgress::Phase phase, int done, int total, bool now) {
    if (!options.on_progress || (!now && elapsed_s() < next_progress_s)) return;
    next_progress_s = elapsed_s() + options.progress_period_s;
    options.on_progress(TransferProgress{phase, done, total, elapsed_s()});
  };
  const auto refuse = [&](const std::string& why) {
    device.setForce(Eigen::Vector3d::Zero());
    result.accepted = false;
    result.refusal = why;
    result.seconds = elapsed_s();
    return result;
  };

  // 1. The workspace: a few probes along the prior's own directions (where its boundary is a
  // measured stop, not a facet's chord that cuts inside a curved boundary), each stop against the
  // prior's reach along the ray from its centre.
  WorkspaceExplorer::Options probe_options;
  probe_options.radial_directions = checkDirections(prior_workspace, options.probe_directions);
  WorkspaceExplorer explorer(parameters, specs, probe_options);
  explorer.start(first.position_m, prior.gravityAt(first.position_m));
  WorkspaceExplorer::Status probe = explorer.state();
  while (probe != WorkspaceExplorer::Status::kFinished &&
         probe != WorkspaceExplorer::Status::kDeviceFault) {
    if (!servo([&](const ServoSample& sample, Eigen::Vector3d& force_n) {
          probe = explorer.step(sample, force_n);
        })) {
      return refuse("the workspace check did not finish within " +
                    std::to_string(options.timeout_s) + " s");
    }
    report(TransferProgress::Phase::kProbing, explorer.probedCount(), explorer.directionCount(),
           false);
  }
  if (probe == WorkspaceExplorer::Status::kDeviceFault) {
    device.setForce(Eigen::Vector3d::Zero());
    throw Error("transfer: the device stopped answering while its workspace was checked");
  }
  result.probe_seconds = elapsed_s();
  report(TransferProgress::Phase::kProbing, explorer.probedCount(), explorer.directionCount(),
         true);
  {
    const ExploredWorkspace probed = explorer.workspace();
    for (std::size_t k = 0; k < probed.directions().size(); ++k) {
      const Eigen::Vector3d ray_m = probed.center_m() +
                                    probed.radii_m()[k] * probed.directions()[k] -
                                    prior_workspace.center_m();
      const double difference_m =
          std::abs(ray_m.norm() - prior_workspace.boundaryDistance_m(ray_m));
      result.prior.workspace_difference_m =
          std::max(result.prior.workspace_difference_m, difference_m);
    }
  }
  if (result.prior.workspace_difference_m > options.max_workspace_difference_m) {
    return refuse("this unit's stops lie up to " +
                  millimetres(result.prior.workspace_difference_m) + " from the prior's (at most " +
                  millimetres(options.max_workspace_difference_m) +
                  " for units of one model): the prior does not fit this unit; run a whole "
                  "calibration");
  }

  // 2. The field at the prior's own measurement points, spread farthest first and measured in
  // batches, each started from the prior's value; every check_every-th point is kept out of the
  // fit to check it. After each batch the candidates are fitted: enough points when the chosen
  // one predicts each fit point from the others within enough_rel, or when another batch would
  // pass the time budget.
  const WorkspaceGrid& grid = prior.grid();
  const std::vector<int> spread = spreadMeasuredVertices(prior, options.max_points);
  MeasurementPlan plan;
  plan.workspace = prior_workspace;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = prior.vertices()[static_cast<std::size_t>(i)];
    plan.points_m.push_back(vertex.measuredAt_m(grid.vertexPosition(i)));
    plan.measure.push_back(isMeasured(vertex));
  }
  // What the probes' carried estimate says this unit adds to the prior (a load, a tilt): the
  // first batch starts from it. Each point must start near its value, or the dither, sized for
  // the start, would take the force past the continuous rating where the unit is heavier.
  const Eigen::Vector3d probe_offset_n =
      explorer.gravity_n() - prior.gravityAt(readServoSample(device).position_m);
  Fit fit;
  std::size_t planned = 0;
  Eigen::Vector3d carried_n = explorer.gravity_n();
  std::vector<int> measured_vertex;  // per entry of result.points_m: its grid vertex
  // Measures `indices` (grid vertices) where `points_plan` says, in a short tour from where the
  // end-effector is, each started from `initial_n[index]`: the calibrator that measured them, or
  // none when the run passed timeout_s. Throws when the device stops answering.
  const auto measure = [&](const MeasurementPlan& points_plan, const std::vector<int>& indices,
                           std::vector<Eigen::Vector3d> initial_n, int done_before,
                           int total) -> std::optional<AutoCalibrator> {
    const ServoSample here = readServoSample(device);
    const Eigen::Vector3d here_m = here.valid ? here.position_m : first.position_m;
    AutoCalibrator::Options calibrator_options;
    calibrator_options.continuous_force_n = continuous_n;
    calibrator_options.initial_estimates_n = std::move(initial_n);
    std::optional<AutoCalibrator> calibrator(std::in_place, grid, parameters,
                                             specs.max_linear_force_n, calibrator_options);
    calibrator->setPlan(points_plan);
    calibrator->visitInOrder(shortTour(indices, points_plan.points_m, here_m));
    calibrator->start(here_m, carried_n);
    AutoCalibrator::Status status = calibrator->state();
    while (status != AutoCalibrator::Status::kFinished &&
           status != AutoCalibrator::Status::kDeviceFault) {
      if (!servo([&](const ServoSample& sample, Eigen::Vector3d& force_n) {
            status = calibrator->step(sample, force_n);
          })) {
        return std::nullopt;
      }
      report(TransferProgress::Phase::kMeasuring, done_before + calibrator->visitedCount(), total,
             status == AutoCalibrator::Status::kVertexFinished);
    }
    if (status == AutoCalibrator::Status::kDeviceFault) {
      device.setForce(Eigen::Vector3d::Zero());
      throw Error("transfer: the device stopped answering while the field was measured");
    }
    return calibrator;
  };
  const auto unset_estimates = [&] {
    return std::vector<Eigen::Vector3d>(
        static_cast<std::size_t>(grid.vertexCount()),
        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  };
  while (planned < spread.size()) {
    const std::size_t batch_size = planned == 0 ? static_cast<std::size_t>(options.first_points)
                                                : static_cast<std::size_t>(options.batch_points);
    const std::size_t end = std::min(spread.size(), planned + batch_size);
    std::vector<Eigen::Vector3d> initial_n = unset_estimates();
    std::optional<Correction> so_far;
    if (fit.ok) so_far.emplace(fit.correction);
    for (std::size_t k = planned; k < end; ++k) {
      const auto index = static_cast<std::size_t>(spread[k]);
      const Eigen::Vector3d& prior_n = prior.vertices()[index].measuredGravity_n();
      initial_n[index] =
          prior_n + (so_far ? so_far->at(plan.points_m[index], prior_n) : probe_offset_n);
    }
    const std::optional<AutoCalibrator> calibrator =
        measure(plan,
                std::vector<int>(spread.begin() + static_cast<std::ptrdiff_t>(planned),
                                 spread.begin() + static_cast<std::ptrdiff_t>(end)),
                std::move(initial_n), static_cast<int>(planned), static_cast<int>(end));
    if (!calibrator) {
      return refuse("the measurements did not finish within " + std::to_string(options.timeout_s) +
                    " s");
    }
    for (std::size_t k = planned; k < end; ++k) {
      const int index = spread[k];
      const VertexEstimate& estimate = calibrator->vertices()[static_cast<std::size_t>(index)];
      if (estimate.outcome != VertexOutcome::kConverged) {
        ++result.failed_points;
        continue;
      }
      ++result.converged_points;
      carried_n = estimate.measuredGravity_n();
      const Eigen::Vector3d point_m = estimate.measuredAt_m(grid.vertexPosition(index));
      result.points_m.push_back(point_m);
      result.prior_n.push_back(prior.gravityAt(point_m));
      result.measured_n.push_back(estimate.measuredGravity_n());
      result.is_check.push_back(static_cast<int>(k) % options.check_every ==
                                options.check_every - 1);
      result.estimates.push_back(estimate);
      measured_vertex.push_back(index);
    }
    planned = end;
    fit = fitCorrection(result);
    const double measured_s = elapsed_s() - result.probe_seconds;
    const double per_point_s = measured_s / static_cast<double>(planned);
    const bool enough = fit.ok && fit.chosen.mean_rel <= options.enough_rel;
    const bool over_budget = elapsed_s() + per_point_s * static_cast<double>(options.batch_points) >
                             options.time_budget_s;
    if (enough || over_budget) break;
  }
  device.setForce(Eigen::Vector3d::Zero());
  result.seconds = elapsed_s();
  result.prior.check_points =
      static_cast<int>(std::count(result.is_check.begin(), result.is_check.end(), true));
  if (!fit.ok || result.prior.check_points < 1) {
    return refuse(std::to_string(result.failed_points) + " of " +
                  std::to_string(result.failed_points + result.converged_points) +
                  " points did not converge: too few to fit and check a correction; run a "
                  "whole calibration");
  }

  // 3. The corrected map, judged where it was not fitted.
  result.scores = fit.scores;
  MapPrior& correction = result.prior;
  correction.correction_model = fit.correction.correction_model;
  correction.gain = fit.correction.gain;
  correction.offset_n = fit.correction.offset_n;
  correction.points_m = fit.correction.points_m;
  correction.residuals_n = fit.correction.residuals_n;
  MapMetadata metadata = prior.metadata();
  metadata.device_serial = specs.serial_number;
  metadata.created_utc.clear();
  metadata.parameters = parameters;
  metadata.field_model = kDefaultFieldModel;
  metadata.curl_weight = 0.0;
  metadata.field_model_scores.clear();
  GravityMap map = correctedMap(prior, correction, std::move(metadata));
  // Each check point's error against the corrected map, in the order of result.points_m.
  std::vector<std::size_t> checks;
  for (std::size_t k = 0; k < result.points_m.size(); ++k) {
    if (result.is_check[k]) checks.push_back(k);
  }
  const auto judge = [&] {
    result.check_errors_rel.clear();
    correction.check_mean_rel = 0.0;
    correction.check_max_rel = 0.0;
    for (std::size_t k : checks) {
      const double error_rel = (map.gravityAt(result.points_m[k]) - result.measured_n[k]).norm() /
                               std::max(result.measured_n[k].norm(), 1e-9);
      result.check_errors_rel.push_back(error_rel);
      correction.check_mean_rel += error_rel;
      correction.check_max_rel = std::max(correction.check_max_rel, error_rel);
    }
    correction.check_mean_rel /= static_cast<double>(correction.check_points);
  };
  judge();
  result.first_check_max_rel = correction.check_max_rel;
  const double tolerance_rel = options.max_check_error_rel;
  if (fit.chosen.mean_rel > options.max_fit_error_rel) {
    return refuse("the best correction (" + correction.correction_model + ") predicts each of " +
                  std::to_string(fit.correction.points_m.size()) +
                  " measurements from the others only within " + percent(fit.chosen.mean_rel) +
                  " of |G| on average (at most " + percent(options.max_fit_error_rel) +
                  "), and misses its check points by up to " + percent(correction.check_max_rel) +
                  ": the prior's unit differs from this one by more than a correction explains "
                  "(another model, a bent link, a heavy tool); run a whole calibration");
  }

  // 4. A check point past the line that stands out from the others is measured again before it
  // can refuse the unit: one measurement (a hold a hand or a cable disturbed, a dither that
  // settled early) must not decide alone. It is measured where it was, the point the check
  // compares the map at; a stop that holds it there moves it back as in the calibration
  // (AutoCalibrator::kStopRetreat_m). The new measurement replaces the first. Points past the
  // line that do not stand out (the whole check is off) refuse at once.
  const std::vector<bool> stands_out =
      standingOut(result.check_errors_rel, options.stand_out_mads, options.stand_out_min_rel);
  std::vector<std::size_t> again;  // indices into `checks`
  for (std::size_t c = 0; c < checks.size(); ++c) {
    if (stands_out[c] && result.check_errors_rel[c] > tolerance_rel) again.push_back(c);
  }
  if (!again.empty()) {
    const double before_s = elapsed_s();
    MeasurementPlan again_plan = plan;
    std::vector<Eigen::Vector3d> initial_n = unset_estimates();
    std::vector<int> indices;
    for (std::size_t c : again) {
      const std::size_t k = checks[c];
      const auto index = static_cast<std::size_t>(measured_vertex[k]);
      const Eigen::Vector3d& point_m = result.points_m[k];
      again_plan.points_m[index] = point_m;
      // Started from the corrected map's value: the best guess there now.
      initial_n[index] = map.gravityAt(point_m);
      indices.push_back(measured_vertex[k]);
    }
    const int total = static_cast<int>(indices.size());
    const std::optional<AutoCalibrator> calibrator =
        measure(again_plan, indices, std::move(initial_n), 0, total);
    if (!calibrator) {
      return refuse("the check points measured again did not finish within " +
                    std::to_string(options.timeout_s) + " s");
    }
    device.setForce(Eigen::Vector3d::Zero());
    for (std::size_t c : again) {
      const std::size_t k = checks[c];
      const VertexEstimate& estimate =
          calibrator->vertices()[static_cast<std::size_t>(measured_vertex[k])];
      // One that does not converge again keeps its first measurement, which then counts.
      if (estimate.outcome != VertexOutcome::kConverged) continue;
      ++result.remeasured_points;
      const Eigen::Vector3d point_m =
          estimate.measuredAt_m(grid.vertexPosition(measured_vertex[k]));
      result.points_m[k] = point_m;
      result.prior_n[k] = prior.gravityAt(point_m);
      result.measured_n[k] = estimate.measuredGravity_n();
      result.estimates[k] = estimate;
    }
    result.remeasure_seconds = elapsed_s() - before_s;
    result.seconds = elapsed_s();
    judge();
  }
  if (correction.check_max_rel > tolerance_rel) {
    const std::string measured_again =
        again.empty() ? std::string()
                      : " after measuring " + std::to_string(again.size()) +
                            " that stood out from the others again (first up to " +
                            percent(result.first_check_max_rel) + ")";
    return refuse("the " + correction.correction_model + " correction misses its " +
                  std::to_string(correction.check_points) + " check points by up to " +
                  percent(correction.check_max_rel) + " of |G|" + measured_again + " (at most " +
                  percent(tolerance_rel) + " allowed; its fit points' leave-one-out error " +
                  percent(fit.chosen.mean_rel) +
                  "): the prior's unit differs from this one by more than a correction explains "
                  "(another model, a bent link, a heavy tool); run a whole calibration");
  }
  // The map keeps the correction as checked.
  MapMetadata kept = map.metadata();
  kept.prior = correction;
  result.map.emplace(map.grid(), map.vertices(), std::move(kept));
  result.accepted = true;
  return result;
}

}  // namespace autograv
