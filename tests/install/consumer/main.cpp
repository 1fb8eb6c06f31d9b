// Uses the installed headers and library: builds a tiny map and interpolates it.
#include <cstdio>
#include <vector>

#include <autograv/map/gravity_map.h>

int main() {
  const autograv::WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
  std::vector<autograv::VertexEstimate> vertices(8);
  for (auto& vertex : vertices) vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, -2.0);
  const autograv::GravityMap map(grid, vertices, autograv::MapMetadata{});
  const Eigen::Vector3d g = map.gravityAt(Eigen::Vector3d(0.01, 0.02, 0.03));
  std::printf("%.3f\n", g.z());
  return g.isApprox(Eigen::Vector3d(0.0, 0.0, -2.0)) ? 0 : 1;
}
