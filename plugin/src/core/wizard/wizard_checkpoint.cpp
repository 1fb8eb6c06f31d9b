// CalibrationWizard, the checkpoint: the vertex mirror the two halves share (the servo half copies
// finished vertices into it with a try-lock it never waits on, the service half reads it), the
// checkpoint file written from it atomically, and a resumed run's restore from that file.
#include <algorithm>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "core/wizard/wizard_impl.h"

namespace autograv {

namespace {

/// The checkpoint at `path` of a run with a device of model `device_model`, or an error that says
/// what to do.
GravityMap loadCheckpointMap(const std::string& path, const std::string& device_model) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) {
    throw Error("no checkpoint " + path +
                " to resume: it is written while a calibration runs and removed once the map is "
                "saved; start afresh (WizardConfig::resume = false)");
  }
  MapLoadOptions options;
  options.expected_device_model = device_model;
  return loadMap(path, options);
}

}  // namespace

std::vector<VertexEstimate> loadCheckpoint(const std::string& path, const WorkspaceGrid& grid,
                                           const std::string& device_model) {
  const GravityMap partial = loadCheckpointMap(path, device_model);
  if (!partial.grid().sameGeometry(grid)) {
    std::ostringstream message;
    message << "checkpoint " << path << " was made for another grid (" << partial.grid().describe()
            << "; this run " << grid.describe()
            << "); use the WizardConfig::centre_m, WizardConfig::grid_resolution and "
               "WizardConfig::advanced.box_size_m of that run";
    throw Error(message.str());
  }
  return partial.vertices();
}

// --- The mirror --------------------------------------------------------------------------------

void CalibrationWizard::Impl::flushMirror() noexcept {
  wizard::TryLock lock(mirror_busy_);
  if (!lock.tryLock()) return;  // service() is reading it: next tick
  const std::vector<VertexEstimate>& vertices = calibrator_->vertices();
  for (std::size_t i = 0; i < copy_pending_.size(); ++i) {
    if (copy_pending_[i] == 0) continue;
    mirror_[i] = vertices[i];  // the mirror's history has the capacity: no allocation
    copy_pending_[i] = 0;
  }
  ++mirror_version_;
  lock.unlock();
  any_copy_pending_ = false;
  mirror_pending_.store(false, std::memory_order_release);
}

std::vector<VertexEstimate> CalibrationWizard::Impl::mirrorCopy(std::uint64_t* version) const {
  wizard::ScopedLock lock(mirror_busy_);
  if (version != nullptr) *version = mirror_version_;
  return mirror_;
}

MapMetadata CalibrationWizard::Impl::metadata() const {
  MapMetadata metadata;
  metadata.device_model = device_->specifications().model_name;
  metadata.device_serial = config_.advanced.device_serial.empty()
                               ? device_->specifications().serial_number
                               : config_.advanced.device_serial;
  metadata.parameters = config_.advanced.parameters;
  metadata.workspace = workspace_;
  metadata.lookup_refinement =
      lookupRefinementFor(grid_, config_.advanced.lookup_refinement, config_.advanced.field_model);
  metadata.field_model = config_.advanced.field_model;
  return metadata;  // created_utc is filled in by saveMap
}

void CalibrationWizard::Impl::writeCheckpoint() {
  if (map_saved_ || !calibrator_) return;
  {
    wizard::ScopedLock lock(mirror_busy_);
    if (mirror_version_ == checkpoint_version_) return;
  }
  std::uint64_t version = 0;
  std::vector<VertexEstimate> vertices = mirrorCopy(&version);
  const int converged = static_cast<int>(std::count_if(
      vertices.begin(), vertices.end(),
      [](const VertexEstimate& vertex) { return vertex.outcome == VertexOutcome::kConverged; }));
  try {
    saveMap(GravityMap(grid_, std::move(vertices), checkpointMetadata(metadata())),
            checkpoint_path_);
    checkpoint_written_ = true;
    checkpointed_converged_ = converged;
    checkpoint_error_.clear();
  } catch (const Error& error) {
    checkpoint_error_ = error.what();  // tried again after the next vertex
  }
  checkpoint_version_ = version;
}

bool CalibrationWizard::Impl::finished() const {
  const WizardStep now = step();
  if (now != WizardStep::kDone && now != WizardStep::kAborted && now != WizardStep::kFault) {
    return false;
  }
  if (mirror_pending_.load(std::memory_order_acquire)) return false;
  if (map_saved_ || !calibrator_) return true;
  wizard::ScopedLock lock(mirror_busy_);
  return mirror_version_ == checkpoint_version_;
}

// --- Resuming ----------------------------------------------------------------------------------

void CalibrationWizard::Impl::restoreCheckpoint(const std::string& device_model) {
  const GravityMap partial = loadCheckpointMap(checkpoint_path_, device_model);
  if (config_.advanced.explore && !config_.advanced.box_size_m) {
    // The grid was fitted to the workspace the interrupted run explored: keep both, at the
    // resolution this run asks for.
    const Eigen::Vector3i resolution = partial.grid().resolution();
    if (resolution != config_.grid_resolution) {
      std::ostringstream message;
      message << "checkpoint " << checkpoint_path_ << " was made on a " << resolution.x() << "x"
              << resolution.y() << "x" << resolution.z() << " grid, this run asks for "
              << config_.grid_resolution.x() << "x" << config_.grid_resolution.y() << "x"
              << config_.grid_resolution.z()
              << "; resume with the WizardConfig::grid_resolution of that run, or start afresh "
                 "(WizardConfig::resume = false)";
      throw Error(message.str());
    }
    grid_ = partial.grid();
  } else if (!partial.grid().sameGeometry(grid_)) {
    loadCheckpoint(checkpoint_path_, grid_, device_model);  // throws, saying what to change
  }
  grid_fixed_ = true;
  workspace_ = partial.metadata().workspace;
  resumed_vertices_ = partial.vertices();
  // The checkpoint's workspace is resumed, not explored again: the exploration's settings would
  // be ignored.
  const WizardConfig::Advanced defaults;
  const bool explorer_set =
      !wizard::sameExplorerOptions(config_.advanced.explorer, defaults.explorer) ||
      !(config_.advanced.min_workspace_extent_m == defaults.min_workspace_extent_m);
  if (!workspace_.empty() && explorer_set) {
    throw Error("checkpoint " + checkpoint_path_ +
                " holds the workspace its run explored, which a resumed run keeps: "
                "WizardConfig::advanced.explorer and advanced.min_workspace_extent_m would be "
                "ignored. Leave them at their defaults to resume, or start afresh "
                "(WizardConfig::resume = false) to explore with them");
  }
}

}  // namespace autograv
