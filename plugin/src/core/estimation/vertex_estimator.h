#pragma once

// Private to core: the inner loop AutoCalibrator runs at each vertex. Programs run it through
// AutoCalibrator or CalibrationWizard; the tests and the research harness include it from here.

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "autograv/device/servo_sample.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/impedance_hold.h"
#include "autograv/types/vertex_estimate.h"
#include "core/estimation/steady_state_detector.h"

namespace autograv {

/// The inner loop of the paper (Section III-B) at one vertex X_i, stepped once per servo tick
/// (every duration in servo time from ServoSample::interval_s, so a late or free-running loop
/// behaves as an exact one):
///   F_j = K_P(i,j) (X_i - X) - K_D(i,j) Xd + G_hat_j                       (eq. 10)
///   K_P(i,j) = beta M_hat_{j-1},  K_D(i,j) = alpha M_hat_{j-1},  M_hat = |G_hat|/g  (eq. 11)
///   at steady state: G_hat_{j+1} = K_P(i,j) (X_i - X_inf) + G_hat_j        (eq. 12)
/// until n_G consecutive updates change G_hat by at most eps_G.
///
/// With EstimationMethod::kDither, eq. 10 also carries a zero-mean dither force and the steady
/// state is that of the mean position over whole dither periods (SteadyStateDetector), so dry
/// friction averages out of eq. 12 instead of biasing it by up to the breakaway force; and an
/// estimate that swings around its fixed point ends with the mean of the swing (kSwingHalf); a
/// step that the end-effector does not follow is looked at again before it counts as a stop
/// (kStopSecondLook_s).
class VertexEstimator {
 public:
  /// What step() did on this tick.
  enum class Status : std::uint8_t {
    kSettling,       ///< Holding X_i, waiting for the steady state of iteration j.
    kUpdated,        ///< This tick ended iteration j with an update (eq. 12).
    kConverged,      ///< Done: n_G consecutive small updates, or a swing (kSwingHalf).
    kIterationCap,   ///< Done: max_iterations reached; the last estimate is kept.
    kNoSteadyState,  ///< Done: an iteration did not settle within max_step_duration_s, close
                     ///< to X_i.
    kUnreachable,    ///< Done: the device cannot be held at X_i: the holding force stayed at
                     ///< the actuator limit, an iteration never settled while more than
                     ///< kUnreachableGap_m away from X_i, or the steady state stalled away from
                     ///< X_i (an end stop, a joint limit, a singular pose) while the estimate
                     ///< kept growing.
    kDeviceFault,    ///< Done: the device stopped answering.
  };

  /// Reserves the history for max_iterations records. `continuous_force_n` is the device's
  /// continuous force rating (continuousForceRating_n), which the automatic dither keeps within;
  /// 0 takes kDefaultContinuousForceFraction of `max_force_n`. Units: [N]. Throws
  /// autograv::Error on bad parameters. Not real-time safe.
  VertexEstimator(const EstimationParameters& parameters, double max_force_n,
                  double continuous_force_n = 0.0);

  /// Begins the inner loop at `vertex_m` with G_hat_0 = `initial_gravity_n` (eqs. 9 and 13: the
  /// gains of iteration 0 come from the same estimate). Real-time safe.
  void start(const Eigen::Vector3d& vertex_m, const Eigen::Vector3d& initial_gravity_n) noexcept;
  /// One servo tick; writes the force to send (clamped to the force limit). Real-time safe.
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;

  /// True once the vertex ended, whatever the outcome. Real-time safe.
  bool finished() const noexcept { return finished_; }
  /// Result so far: G_hat, iterations, seconds, outcome and history. Real-time safe to read.
  const VertexEstimate& estimate() const noexcept { return estimate_; }
  /// The vertex X_i being held. Unit: [m]
  const Eigen::Vector3d& vertex_m() const noexcept { return vertex_m_; }
  /// Iteration in progress (0-based), i.e. the number of updates so far.
  int iteration() const noexcept { return estimate_.iterations; }
  /// Most recent ||Delta_j||, NaN before the first update. Unit: [m]
  double lastPositionError_m() const noexcept { return last_error_m_; }
  /// Current proportional gain K_P(i,j). Unit: [N/m]
  double stiffness_n_per_m() const noexcept { return stiffness_n_per_m_; }
  /// Dither amplitude per axis in use (0 with the paper's method). Unit: [N]
  double ditherAmplitude_n() const noexcept { return dither_amplitude_n_; }

  /// The dither amplitude picked when EstimationParameters::dither_amplitude_n is 0, for a vertex
  /// whose estimate is `gravity_n` in magnitude: kAutoDitherFraction of `max_force_n`, lowered
  /// so that |G_hat| plus the dither's largest magnitude (sqrt(2) times the amplitude) stays
  /// within kContinuousForceMargin of `continuous_force_n`, but not below
  /// EstimationParameters::kMinAutoDither_n. Units: [N]. Real-time safe.
  static double automaticDitherAmplitude_n(double max_force_n, double continuous_force_n,
                                           double gravity_n) noexcept;
  /// Fraction of the continuous rating the automatic dither plans to use at its peaks, leaving
  /// room for the hold's feedback force.
  static constexpr double kContinuousForceMargin = 0.95;

  /// Floor on |G_hat| used for the gains, enforcing the paper's constraint (6): the
  /// ImpedanceHold floor of the estimator, the calibrator's moves and the wizard. Unit: [N]
  static constexpr double kMinGravityN = 0.01;
  /// Consecutive updates that do not shrink (each at least kStallRatio of the one before and
  /// larger than kStallUpdateFloor_n and 4 eps_G) after which the vertex is unreachable. Near a
  /// reachable vertex eq. (12) contracts the update by about |dG/dX| / K_P (a tenth to a third
  /// on the simulated devices) per iteration and friction leaves updates of a few mN; against an
  /// end stop the steady state stays put and every update is K_P times the same gap.
  static constexpr int kStalledUpdates = 3;
  /// Estimates in each half of the swing rules' window. A vertex that has iterated twice this
  /// many times swings around its fixed point (a steep field, a jittery loop, high friction): it
  /// ends when the n_G rule holds or when the means of its last two halves of this many
  /// estimates agree within eps_G, and either way with the mean of both halves. Dither method
  /// only: the paper's method keeps its own stop rule.
  static constexpr int kSwingHalf = 8;
  /// An update of at least this many eps_G is a step of the approach to the fixed point, not of
  /// a swing around it (those stay within a few eps_G): the swing's mean starts after it.
  static constexpr double kApproachSteps = 10.0;
  /// See kStalledUpdates: an update at least this fraction of the previous one does not shrink.
  static constexpr double kStallRatio = 0.6;
  /// See kStalledUpdates: updates below this never count as stalled. Unit: [N]
  static constexpr double kStallUpdateFloor_n = 0.02;
  /// Distance from X_i beyond which a hold that never settles means the vertex is out of reach:
  /// well above the steady-state offsets friction leaves (0.1 mm on the simulated devices).
  /// Unit: [m]
  static constexpr double kUnreachableGap_m = 2e-3;
  /// Where G changes faster than the hold is stiff (c above K_P / 2, the paper's condition (6)
  /// broken: near a singular pose of a parallel arm), eq. (12) overshoots: each step reverses the
  /// last one without shrinking. A reversal that keeps more than kOvershootRatio of the previous
  /// step's length scales the steps that follow by the relaxation that would have cancelled it
  /// (1 / (1 - ratio) for a linear field): the fixed point, G_hat = G(X_i), is the same.
  static constexpr double kOvershootRatio = 0.3;
  /// Smallest relaxation: a step reversing with ratio -4 or worse is not followed any further.
  static constexpr double kMinRelaxation = 0.2;
  /// A stop holds the end-effector when two steps in a row push the same way without shrinking
  /// while the steady state moves by less than this fraction of what the first step should have
  /// moved it (its length over K_P): the force grows, the position does not follow. A stop is
  /// a spring 30 or more times stiffer than the hold (1500-2000 N/m on the simulators, a rigid
  /// body on hardware); a field that steep elsewhere (up to 9 K_P) still counts as free space.
  /// With the dither method only: without a dither, dry friction holds the end-effector still
  /// too, until the force breaks it away. A step that looks held is looked at again under the
  /// same force (kStopSecondLook_s) and is a stop only if it still looks held. The vertex then
  /// ends kUnreachable with stopContact() set, after two updates instead of kStalledUpdates.
  static constexpr double kStopFollowFraction = 0.1;
  /// Shortest second look at a step that seemed held by a stop. A desktop loop's steady state
  /// may come while the end-effector still creeps toward X_i under the dither (0.4 mm/s next to
  /// sim:falcon's -x stop); in 0.5 s such a creep moves past kStopFollowFraction, a stop does
  /// not (its settled position moves by 0.01-0.08 mm between the looks). Unit: [s]
  static constexpr double kStopSecondLook_s = 0.5;

  /// The creep rule. Next to a stop that holds the end-effector a little short of X_i (tenths
  /// of a millimetre, sim:falcon at a 1.5-2 mm boundary margin), every step of eq. (12) lies
  /// below the stall floor and shrinks only by K_P / (K_P + k_stop) per iteration: the estimate
  /// absorbs the stop's reaction (up to 0.3 N) before the n_G rule ends the vertex. A run of
  /// kCreepUpdates updates whose parts along the outward direction (setOutward) are each at
  /// least kCreepFloor eps_G, while the steady state follows along it by less than kCreepFollow
  /// of what the hold's spring should have moved it (at least kCreepMinExpected_m in all), is
  /// suspected; the push test (kCreepProbe_m) decides. Dither method only.
  static constexpr int kCreepUpdates = 3;
  static constexpr double kCreepFloor = 0.25;
  static constexpr double kCreepFollow = 0.25;
  /// A run is suspected when its steady state follows by less than this share of what the
  /// steps should have moved it: a dither that only grazes the stop lets it follow by a quarter
  /// or so (a point 0.1 mm from a 2000 N/m stop: 26 %), free space by nearly all; the push test
  /// (kCreepFollow of kCreepProbe_m) tells the two apart.
  static constexpr double kCreepSuspectFollow = 0.5;
  static constexpr double kCreepMinExpected_m = 0.02e-3;
  /// The push test of a suspected creep: the hold target moves this far along the outward
  /// direction for one steady state, G_hat unchanged. Free space follows by most of it
  /// (sim:omni, whose friction under the dither makes runs that look held: 0.33-0.35 mm), a
  /// stop by less than kCreepFollow of it (sim:falcon: 0.01-0.04 mm). A stop ends the vertex as
  /// the held-still rule does, with G_hat from before the run; otherwise the target goes back
  /// and the iteration goes on. Unit: [m]
  static constexpr double kCreepProbe_m = 0.5e-3;
  /// The outward direction at X_i (any length), which turns the creep rule and the push test
  /// on for this vertex; start() turns them off. `push` (any length) is the direction the push
  /// test pushes along, zero for `outward` itself: next to an edge or a corner of the boundary
  /// the caller may tilt it toward every face within reach, so that it presses into each.
  /// Call after start(). Real-time safe.
  void setOutward(const Eigen::Vector3d& outward,
                  const Eigen::Vector3d& push = Eigen::Vector3d::Zero()) noexcept {
    outward_ = outward;
    push_direction_ = push.squaredNorm() > 0.0 ? push : outward;
  }

  /// The push test (the stop watch of a hold next to the boundary). A stop across gravity (a
  /// floor, a ceiling) pushes along the very component eq. (12) converges on, and a stop that
  /// the dither merely grazes bends each update by a few mN: such a hold converges with the
  /// stop's reaction in G_hat (a flat 3000 N/m ceiling 0.15 mm into the point: 20 % of |G|) and
  /// no creep run ever starts. So a vertex with an outward direction (setOutward) that is about
  /// to end converged, and whose estimate moved toward the stop since G_hat_0 by more than
  /// kPushTrigger eps_G (the stop's reaction adds along the push; what is smaller than that costs
  /// the map less than a push costs the calibration), is first pushed: the hold target moves
  /// kPushProbe_m along the push direction for one steady state (kPushSteadyWindows), G_hat
  /// unchanged, and the steady state's displacement from the converged one is read as a vector.
  ///   - It follows by at least kPushFreeFollow along the push: free, the vertex converges.
  ///   - It follows by less than kPushBlockedFollow: a stop holds it (or the hold lies deep in
  ///     a stop, whose absorbed reaction then blocks an inward push too: no reference helps).
  ///   - Otherwise, the reference: the target moves kPushProbe_m the other way (inward) for one
  ///     steady state. Friction under the dither is symmetric, so free space follows both
  ///     pushes alike; a stop blocks the outward one, or part of it. The vertex ends against a
  ///     stop when the outward displacement, mirrored, strays from the inward one by more than
  ///     kPushAsymmetry of the larger of the two (grazing: 0.69-0.79), or when the outward one
  ///     went sideways of the push by more than kPushSideways of the probe (an edge, whose stop
  ///     blocks the part of the push along its own normal: 0.44 for a push 45 degrees to a
  ///     1000 N/m floor, 0.39 measured), and converges otherwise.
  /// A stop ends the vertex kUnreachable with stopContact() set (contactPosition_m(): the
  /// converged steady state; contactDirection(): the push direction; gravityBeforeContact_n():
  /// the vertex's initial estimate, which the stop's reaction had no part in), as the creep
  /// rule's confirmed stop does. Dither method only.
  /// Measured on the Omega-like point mass in a +/-40 mm box (tests/core/estimation/
  /// stop_watch_test.cpp), stops of 1000-5000 N/m, typical and high friction: 1000 free holds
  /// 1.5-5 mm from a face or an edge follow the outward push by 0.90-1.0 of it, sideways by at
  /// most 0.07; a hold grazing a floor or a ceiling follows by 0.22-0.32 and the inward push by
  /// 0.97-1.07; an edge's floor lets 0.47-0.59 through. In whole default calibrations
  /// (sim:omni, sim:falcon, sim:omega, sim:swirl-cube) free pushes follow by more than 0.65 but
  /// for a few on sim:falcon and sim:omni (down to 0.16: those that a stop holds). Unit: [m]
  static constexpr double kPushProbe_m = 0.5e-3;
  /// Along-push following (of kPushProbe_m) above which the hold is free. Unit: [1]
  static constexpr double kPushFreeFollow = 0.65;
  /// Along-push following below which a stop holds the hold. Unit: [1]
  static constexpr double kPushBlockedFollow = 0.2;
  /// Largest mismatch of the mirrored outward and the inward displacement, as a share of the
  /// larger, in free space (friction: 0.0-0.2 on the simulators). Unit: [1]
  static constexpr double kPushAsymmetry = 0.45;
  /// Largest sideways part of the outward displacement, as a share of kPushProbe_m, of a push
  /// that followed only partly (0.2-0.65) in free space: 0.07 on the point mass; in whole
  /// calibrations a few reach 0.3 (one more retreat on sim:falcon seed 3), while an edge's
  /// floor sends 0.39-0.44 sideways. Unit: [1]
  static constexpr double kPushSideways = 0.25;
  /// Outward move of the estimate over the vertex, in eps_G, that calls for the push test. On
  /// default calibrations 2 pushes 15-37 points (sim:omni to sim:swirl-cube); 1 pushed a
  /// third more, for 8-26 s of device time instead of 4-23 s (both before
  /// kPushWindowTolerance), and caught one more stop on sim:swirl-cube seed 1. A reaction that
  /// moves the estimate by less than 2 eps_G is under 0.5 % of sim:omega's |G|. Unit: [eps_G]
  static constexpr double kPushTrigger = 2.0;
  /// Window pairs that make a push's steady state: one, as the displacement read is tenths of a
  /// millimetre (kPushWindowTolerance), not the eps_G-sized change eq. (12) needs.
  static constexpr int kPushSteadyWindows = 1;
  /// Window means of a push's steady state agree within this share of kPushProbe_m (25 um),
  /// not a quarter of eps_G / K_P (8 um on sim:omega): the verdict needs a tenth of the probe,
  /// and the push's transient decays to the looser bound sooner. Default calibrations: 3.6-4.5 s
  /// more device time on sim:falcon instead of 8.5-18.7 s, 6.7-7.4 s on sim:omega instead of
  /// 9.6-9.8 s. Unit: [1]
  static constexpr double kPushWindowTolerance = 0.05;
  /// The last push test's displacements of the steady state from the converged one: under the
  /// outward push, and under the inward one (zero when it was not needed). Unit: [m]
  const Eigen::Vector3d& pushOutwardMoved_m() const noexcept { return push_outward_moved_m_; }
  const Eigen::Vector3d& pushInwardMoved_m() const noexcept { return push_inward_moved_m_; }
  /// Push tests begun since construction (for the cost of the stop watch).
  int pushTests() const noexcept { return push_tests_; }
  /// True when the vertex ended against a stop (kStopFollowFraction). Real-time safe.
  bool stopContact() const noexcept { return stop_contact_; }
  /// Where the stop held the end-effector (the last steady state). Unit: [m]
  const Eigen::Vector3d& contactPosition_m() const noexcept { return contact_position_m_; }
  /// Unit vector from the contact toward X_i, i.e. into the stop. Zero without a contact.
  const Eigen::Vector3d& contactDirection() const noexcept { return contact_direction_; }
  /// G_hat before the stop's reaction entered it (the estimate the first pushing step started
  /// from). Unit: [N]
  const Eigen::Vector3d& gravityBeforeContact_n() const noexcept {
    return gravity_before_contact_n_;
  }

 private:
  void setGains(const Eigen::Vector3d& gravity_n) noexcept;
  /// A new steady-state observation: detector and dither phase from zero.
  void restartObservation(int required_steady) noexcept;
  void finish(VertexOutcome outcome) noexcept;
  // Ends the vertex against a stop that held the end-effector at `contact_m`, pushing along
  // `direction` (into the stop), with G_hat back at `gravity_before_n` (before its reaction).
  Status endAgainstStop(const Eigen::Vector3d& contact_m, const Eigen::Vector3d& direction,
                        const Eigen::Vector3d& gravity_before_n) noexcept;
  Eigen::Vector3d ditherForce_n(double cell) const noexcept;
  Eigen::Vector3d ditherImpulse_ns(double from, double to) const noexcept;
  // The waveform an exact loop would send now; `payback_n` is what late or early ticks owe it.
  Eigen::Vector3d ditherWaveform_n(double periods, Eigen::Vector3d& payback_n) noexcept;
  Eigen::Vector3d holdPayback_n(const Eigen::Vector3d& feedback_n, double periods) noexcept;
  // The hold plus the dither, and as much of the paybacks as the continuous rating leaves room
  // for: what is not sent now stays owed (the debts count what was sent).
  Eigen::Vector3d ditheredHoldForce_n(const Eigen::Vector3d& feedback_n, double periods) noexcept;
  // Samples (paper) or windows (dither) that make the next steady state.
  int requiredSteadyCount(bool last_update_small) const noexcept;

  EstimationParameters parameters_;
  double max_force_n_;
  double continuous_force_n_;  // the automatic dither's budget. Unit: [N]
  ImpedanceHold hold_;         // eq. (10) with eq. (11)'s gains, floored at kMinGravityN
  SteadyStateDetector detector_;
  VertexEstimate estimate_;
  Eigen::Vector3d vertex_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_n_ = Eigen::Vector3d::Zero();  // G_hat_j, the feedforward
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  double mass_kg_ = 0.0;            // M_hat_{j-1} of the gains in use (eq. 11). Unit: [kg]
  double stiffness_n_per_m_ = 0.0;  // K_P = beta M_hat_{j-1}. Unit: [N/m]
  double last_error_m_ = 0.0;
  double elapsed_periods_ = 0.0;  // servo time at this vertex, in nominal periods
  int small_updates_ = 0;
  int stalled_updates_ = 0;
  double last_update_n_ = 0.0;  // |G_hat_j - G_hat_{j-1}| of the previous update. Unit: [N]
  Eigen::Vector3d last_raw_update_n_ = Eigen::Vector3d::Zero();  // eq. (12)'s previous step. [N]
  std::array<Eigen::Vector3d, 2 * kSwingHalf> recent_n_{};       // last estimates, a ring. [N]
  int swing_estimates_ = 0;  // estimates since the last large step, the last one included
  double relaxation_ = 1.0;  // fraction of eq. (12)'s step applied (kMinRelaxation..1)
  Eigen::Vector3d last_settled_m_ = Eigen::Vector3d::Zero();   // previous steady state. [m]
  Eigen::Vector3d last_previous_n_ = Eigen::Vector3d::Zero();  // G_hat before the last step. [N]
  bool stop_contact_ = false;
  Eigen::Vector3d outward_ = Eigen::Vector3d::Zero();  // creep rule on when nonzero
  int creep_count_ = 0;                                // updates in the current run
  double creep_expected_m_ = 0.0;  // how far the run's applied steps should have moved X. [m]
  Eigen::Vector3d creep_start_settled_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d creep_start_gravity_n_ = Eigen::Vector3d::Zero();  // G_hat before the run
  bool creep_probe_ = false;                                         // push test under way
  Eigen::Vector3d creep_probe_offset_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d creep_probe_base_m_ = Eigen::Vector3d::Zero();
  // The push test (kPushProbe_m): 0 none, 1 outward, 2 inward.
  enum class PushPhase : std::uint8_t { kNone, kOutward, kInward };
  // Begins the push test at the converged steady state `settled_m`.
  void beginPush(const Eigen::Vector3d& settled_m) noexcept;
  // The push test's steady state: kSettling while it goes on, else the vertex's end.
  Status pushSettled(const Eigen::Vector3d& settled_m) noexcept;
  Eigen::Vector3d push_direction_ = Eigen::Vector3d::Zero();  // push test on when nonzero
  PushPhase push_phase_ = PushPhase::kNone;
  Eigen::Vector3d push_base_m_ = Eigen::Vector3d::Zero();  // the converged steady state. [m]
  Eigen::Vector3d push_outward_moved_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d push_inward_moved_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d initial_gravity_n_ = Eigen::Vector3d::Zero();  // G_hat_0 at this vertex. [N]
  int push_tests_ = 0;
  bool stop_second_look_ = false;  // a held step is being looked at again (kStopFollowFraction)
  double second_look_start_periods_ = 0.0;  // elapsed_periods_ when the second look began
  Eigen::Vector3d contact_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d contact_direction_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gravity_before_contact_n_ = Eigen::Vector3d::Zero();
  double saturated_periods_ = 0.0;  // servo time at the force limit, in nominal periods
  double invalid_periods_ = 0.0;    // servo time of consecutive bad samples
  double max_saturated_periods_ = 0.0;
  double max_invalid_periods_ = 0.0;
  bool finished_ = true;
  double dither_amplitude_n_ = 0.0;  // 0: no dither (paper's method)
  double dither_step_rad_ = 0.0;     // dither phase advance per nominal servo period
  double dither_periods_ = 0.0;      // servo time since the iteration's first sample
  bool dither_started_ = false;
  Eigen::Vector3d last_dither_n_ = Eigen::Vector3d::Zero();   // dither part of the last command
  Eigen::Vector3d dither_debt_ns_ = Eigen::Vector3d::Zero();  // impulse sent minus the waveform's
  Eigen::Vector3d dither_displacement_debt_ = Eigen::Vector3d::Zero();
  double mean_interval_periods_ = 1.0;  // recent servo interval, in nominal periods
  bool hold_started_ = false;
  Eigen::Vector3d last_feedback_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hold_debt_ns_ =
      Eigen::Vector3d::Zero();  // feedback impulse beyond an exact loop's
  Eigen::Vector3d last_hold_payback_n_ = Eigen::Vector3d::Zero();
};

const char* toString(VertexEstimator::Status status) noexcept;

}  // namespace autograv
