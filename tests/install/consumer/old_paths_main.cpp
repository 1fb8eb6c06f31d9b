// Written against autograv 0.1's flat header paths: still builds and runs with 0.2, whose
// forwarding headers point to the new ones.
#include <cstdio>
#include <vector>

#include <autograv/calibration_wizard.h>
#include <autograv/gravity_compensated_device.h>
#include <autograv/gravity_map.h>
#include <autograv/map_io.h>
#include <autograv/workspace_grid.h>

int main() {
  const autograv::WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
  std::vector<autograv::VertexEstimate> vertices(8);
  for (auto& vertex : vertices) vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, 1.5);
  autograv::MapMetadata metadata;
  metadata.device_model = "consumer:old-paths";  // maps are tied to a device model
  const autograv::GravityMap map(grid, vertices, metadata);
  const std::string text = autograv::mapToJson(map);
  std::printf("old paths: %.3f N, %zu bytes of JSON\n", map.gravityAt(Eigen::Vector3d::Zero()).z(),
              text.size());
  return text.empty() ? 1 : 0;
}
