#include "render/offscreen_renderer.h"

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>

#include "core/check.h"
#include "core/errors.h"

namespace ihs::render {

void UseMachineIndependentRasteriser() { setenv("GALLIUM_DRIVER", "softpipe", /*overwrite=*/0); }

void RendererOptions::Check() const {
  IHS_CHECK_ARG(near_mm > 0, "renderer.near_mm must be positive, got " << near_mm);
  IHS_CHECK_ARG(far_mm > near_mm, "renderer.far_mm must exceed near_mm, got " << far_mm);
}

std::vector<std::uint16_t> RenderOutput::DepthMillimetres() const {
  std::vector<std::uint16_t> out(depth_mm.size(), 0);
  for (size_t i = 0; i < depth_mm.size(); ++i) {
    const float d = depth_mm[i];
    if (d > 0 && d < 65535.f) out[i] = static_cast<std::uint16_t>(std::lround(d));
  }
  return out;
}

struct OffscreenRenderer::Context {
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> buffer;  // RGBA colour buffer OSMesa draws into.
  ~Context() {
    if (context) OSMesaDestroyContext(context);
  }
};

OffscreenRenderer::OffscreenRenderer(const CameraIntrinsics& intrinsics, RendererOptions options)
    : intrinsics_(intrinsics), options_(options), context_(std::make_unique<Context>()) {
  intrinsics_.Check();
  options_.Check();
  context_->context = OSMesaCreateContextExt(OSMESA_RGBA, 32, 0, 0, nullptr);
  if (!context_->context)
    context_->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (!context_->context) throw DeviceError("OSMesa cannot create an off-screen GL context");
  context_->buffer.resize(static_cast<size_t>(intrinsics_.width) * intrinsics_.height * 4);
}

OffscreenRenderer::~OffscreenRenderer() = default;

RenderOutput OffscreenRenderer::Render(const std::vector<RenderItem>& items) {
  const int width = intrinsics_.width, height = intrinsics_.height;
  if (!OSMesaMakeCurrent(context_->context, context_->buffer.data(), GL_UNSIGNED_BYTE, width,
                         height)) {
    throw DeviceError("OSMesa cannot make its context current");
  }
  const double n = options_.near_mm, f = options_.far_mm;
  // OpenCV camera (x right, y down, z forward) → OpenGL eye (x right, y up, z backward), and a
  // projection that puts pixel centre (u, v) at window (u + 0.5, height − v − 0.5).
  const double fx = intrinsics_.fx, fy = intrinsics_.fy, cx = intrinsics_.cx, cy = intrinsics_.cy;
  const GLdouble projection[16] = {// Column-major.
                                   2 * fx / width,
                                   0,
                                   0,
                                   0,
                                   0,
                                   2 * fy / height,
                                   0,
                                   0,
                                   1 - 2 * (cx + 0.5) / width,
                                   1 - 2 * (height - 0.5 - cy) / height,
                                   -(f + n) / (f - n),
                                   -1,
                                   0,
                                   0,
                                   -2 * f * n / (f - n),
                                   0};
  glViewport(0, 0, width, height);
  glMatrixMode(GL_PROJECTION);
  glLoadMatrixd(projection);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glScaled(1, -1, -1);  // OpenCV camera frame → GL eye frame.
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glClearDepth(1.0);

  RenderOutput output;
  output.width = width;
  output.height = height;
  const size_t pixels = static_cast<size_t>(width) * height;

  // Pass 1: shaded colour and depth. A light at the camera: brightness = |n·view|.
  const auto& bg = options_.background;
  glClearColor(bg[0] / 255.f, bg[1] / 255.f, bg[2] / 255.f, 1.f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  auto draw = [&](bool shaded) {
    glBegin(GL_TRIANGLES);
    for (const RenderItem& item : items) {
      if (!item.mesh) continue;
      const TriangleMesh& mesh = *item.mesh;
      for (const TriangleMesh::Face& face : mesh.faces) {
        Eigen::Vector3d corners[3];
        for (int k = 0; k < 3; ++k)
          corners[k] = item.cam_from_mesh * Eigen::Vector3d(mesh.vertices[face[k]].cast<double>());
        const Eigen::Vector3d normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        const Eigen::Vector3d centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        const double norm = normal.norm() * centre.norm();
        const double shade = norm > 0 ? 0.25 + 0.75 * std::abs(normal.dot(centre)) / norm : 1.0;
        for (int k = 0; k < 3; ++k) {
          if (shaded) {
            const auto& c =
                item.use_vertex_colors && mesh.HasColors() ? mesh.colors[face[k]] : item.color;
            glColor3d(c[0] / 255.0 * shade, c[1] / 255.0 * shade, c[2] / 255.0 * shade);
          } else {
            glColor3ub(item.label, 0, 0);
          }
          glVertex3d(corners[k].x(), corners[k].y(), corners[k].z());
        }
      }
    }
    glEnd();
  };
  draw(true);
  glFinish();
  std::vector<GLuint> depth(pixels);
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, depth.data());
  output.rgb.resize(pixels * 3);
  output.depth_mm.assign(pixels, 0.f);
  for (int row = 0; row < height; ++row) {
    const int v = height - 1 - row;  // GL rows start at the bottom.
    for (int u = 0; u < width; ++u) {
      const size_t gl = static_cast<size_t>(row) * width + u;
      const size_t out = static_cast<size_t>(v) * width + u;
      for (int c = 0; c < 3; ++c) output.rgb[3 * out + c] = context_->buffer[4 * gl + c];
      const double d = depth[gl] / 4294967295.0;
      if (d < 1.0) {
        const double z_ndc = 2 * d - 1;
        output.depth_mm[out] = static_cast<float>(2 * f * n / ((f + n) - z_ndc * (f - n)));
      }
    }
  }

  // Pass 2: labels, unshaded, with the same depth test.
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  draw(false);
  glFinish();
  output.labels.resize(pixels);
  for (int row = 0; row < height; ++row) {
    const int v = height - 1 - row;
    for (int u = 0; u < width; ++u) {
      output.labels[static_cast<size_t>(v) * width + u] =
          context_->buffer[4 * (static_cast<size_t>(row) * width + u)];
    }
  }
  return output;
}

}  // namespace ihs::render
