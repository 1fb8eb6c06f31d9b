#pragma once

#include <CLI/CLI.hpp>

#include "autograv/estimation/workspace_explorer.h"

namespace autograv::cli {

/// Adds --boundary-probes N to `command`: how many boundary probes the exploration makes after
/// its radial ones, each from just inside the boundary those found, where that boundary bulges
/// most beyond the triangles between the radial stops (WorkspaceExplorer::Options::
/// boundary_directions, whose default `count` keeps when the option is not given). AdvancedOptions
/// declares it once for calibrate and wizard.
inline CLI::Option* addBoundaryProbesOption(CLI::App& command, int& count) {
  return command
      .add_option("--boundary-probes", count,
                  "After the radial probes, refine the workspace's boundary with N more probes "
                  "where it bulges most beyond the triangles between the radial stops, each from "
                  "just inside it (about 1 s each; 0: none)")
      ->check(CLI::Range(0, 2000))
      ->capture_default_str();
}

}  // namespace autograv::cli
