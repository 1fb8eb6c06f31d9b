#pragma once

// Per-vertex statistics of a calibration: what "failed" means, the median, and the counts and
// spreads every tool reports (calibrate, bench, the wizard's review, the scene), said once; and
// how a map corrected from another unit's map says where it came from.

#include <string>
#include <vector>

#include "autograv/map/gravity_map.h"

namespace autograv {

/// True for a vertex held at a reachable point that did not converge there: it hit the iteration
/// cap, never settled, saturated or its device faulted. A pending vertex (never visited), an
/// unreachable one (solved from its neighbours, never redone) and one left out (measured twice,
/// contradicted both times) are not failed. Real-time safe.
bool isFailed(const VertexEstimate& vertex) noexcept;

/// True for a visited vertex the map holds no value for: a failed one, or an unreachable one that
/// fillUnreachableVertices had no converged vertex to solve from; a value solved from the
/// measurements (VertexProvenance::kFilled) is a value. What the scene marks red.
/// Real-time safe.
bool holdsNoValue(const VertexEstimate& vertex) noexcept;

/// True for a vertex a redo pass visits again: a failed one, or one never visited (an
/// unreachable vertex would meet the same stop again). Real-time safe.
bool needsAnotherVisit(const VertexEstimate& vertex) noexcept;

/// The middle value of `values`, or the mean of the two middle ones; 0 when there is none.
/// Not real-time safe (sorts its copy).
double median(std::vector<double> values);

/// Fewest, median and most iterations over a set of vertices (all 0 for an empty set).
struct IterationSpread {
  int min = 0;          ///< Fewest iterations.
  double median = 0.0;  ///< Median iterations (median()).
  int max = 0;          ///< Most iterations.
};

/// The statistics of the converged vertices alone (what the wizard's review shows).
struct ConvergedVertexStats {
  IterationSpread iterations;  ///< Their iterations.
  /// Their servo time, moves excluded, summed in index order. Unit: [s]
  double seconds = 0.0;
  double gravity_min_n = 0.0;  ///< Smallest |G_hat| (0 when none). Unit: [N]
  double gravity_max_n = 0.0;  ///< Largest |G_hat| (0 when none). Unit: [N]
};

/// The per-vertex statistics of a run or a map, over its vertices in index order.
struct MapSummary {
  int vertices = 0;     ///< Vertices of the grid.
  int converged = 0;    ///< Outcome kConverged.
  int pending = 0;      ///< Outcome kPending: never visited.
  int unreachable = 0;  ///< Outcome kUnreachable.
  int left_out = 0;     ///< Outcome kLeftOut: measured, contradicted, left out of the fit.
  int filled = 0;       ///< Provenance kFilled: solved from the measurements.
  /// Value kinds (valueKind): measured at the vertex, measured inside the stops, solved.
  int at_vertex = 0;
  int off_vertex = 0;  ///< ValueKind::kOffVertex.
  int solved = 0;      ///< ValueKind::kSolved.
  /// Indices of the failed vertices (isFailed), ascending.
  std::vector<int> failed;
  /// Indices of the vertices a redo pass visits (needsAnotherVisit), ascending.
  std::vector<int> to_visit_again;
  /// Iterations over every vertex (unvisited ones count 0).
  IterationSpread iterations;
  /// Servo time at every vertex, moves excluded, summed in index order. Unit: [s]
  double seconds = 0.0;
  /// seconds / vertices (NaN for no vertex). Unit: [s]
  double secondsPerVertex() const noexcept { return seconds / vertices; }
  /// The same statistics over the converged vertices alone.
  ConvergedVertexStats converged_only;
};

/// The statistics of `vertices`. Not real-time safe.
MapSummary summarizeVertices(const std::vector<VertexEstimate>& vertices);

/// Where a map corrected from another unit's map came from (MapMetadata::prior), in the two rows
/// `inspect` prints.
struct PriorText {
  /// "map of unit <serial, or (no serial)> made <created_utc> (<source>)".
  std::string made_from;
  /// "<model> from <n> points; gain diag g_xx / g_yy / g_zz, offset [x, y, z] mN; checked on <k>
  /// points: mean m %, largest l %; workspace within d mm".
  std::string correction;
};

/// The text of `prior`. Not real-time safe.
PriorText describePrior(const MapPrior& prior);

}  // namespace autograv
