#pragma once
// Pictures of meshes for the report: every method's scan of an object drawn the same way from
// the same side (grey, shaded), placed in the true object's frame, like the paper's comparison
// figure.

#include <cstdint>
#include <memory>
#include <vector>

#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace ihs::render {
class OffscreenRenderer;
}

namespace ihs::bench {

class MeshView {
 public:
  /// Square images of `size` pixels. Throws ihs::DeviceError when OSMesa cannot start.
  explicit MeshView(int size = 320);
  ~MeshView();

  /// Draws `mesh` placed by `truth_from_mesh`, seen from the side and a little above (the true
  /// object's axis +z up), framing the sphere of `radius_mm` around `center` (the true object's
  /// frame) so that all methods' scans of one object are drawn at one scale. RGB8, size².
  std::vector<std::uint8_t> Draw(const TriangleMesh& mesh, const Rigid3& truth_from_mesh,
                                 const Eigen::Vector3d& center, double radius_mm);
  int size() const { return size_; }

 private:
  int size_;
  std::unique_ptr<render::OffscreenRenderer> renderer_;
};

}  // namespace ihs::bench
