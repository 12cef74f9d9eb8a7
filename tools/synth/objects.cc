#include "tools/synth/objects.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/check.h"
#include "core/data_lines.h"
#include "core/errors.h"

namespace ihs::synth {
namespace {

// Appends points (z, r) along a circular arc in the profile plane.
void Arc(LatheProfile& profile, double center_z, double radius, double from_deg, double to_deg,
         int steps) {
  for (int i = 0; i <= steps; ++i) {
    const double a = (from_deg + (to_deg - from_deg) * i / steps) * M_PI / 180.0;
    profile.emplace_back(center_z + radius * std::sin(a), std::abs(radius * std::cos(a)));
  }
}

void Check(const LatheProfile& profile, const std::string& where) {
  if (profile.size() < 2) throw InputError(where + ": a lathe profile needs at least 2 points");
  for (size_t i = 0; i < profile.size(); ++i) {
    const auto [z, r] = profile[i];
    if (!std::isfinite(z) || !std::isfinite(r) || r < 0) {
      throw InputError(where + ": point " + std::to_string(i + 1) + " has a bad height or radius");
    }
    if (i > 0 && z < profile[i - 1].first) {
      throw InputError(where + ": heights must not decrease (point " + std::to_string(i + 1) + ")");
    }
  }
  if (profile.back().first - profile.front().first <= 0) throw InputError(where + ": zero height");
}

}  // namespace

std::vector<std::string> PaperObjectNames() {
  return {"sphere", "water-bottle", "bowling-pin", "small-bottle"};
}

LatheProfile PaperObjectProfile(const std::string& name) {
  LatheProfile p;
  if (name == "sphere") {
    Arc(p, 35, 35, -90, 90, 90);  // Ø70.
  } else if (name == "water-bottle") {
    // Ø73 × 218: rounded base edge, straight body, shoulder, neck Ø28 and cap.
    p = {{0, 0},    {0, 33.5}, {0.9, 35.6}, {3, 36.5}, {150, 36.5},
         {170, 32}, {185, 22}, {195, 14},   {218, 14}, {218, 0}};
  } else if (name == "bowling-pin") {
    // Height 268, body Ø82 at its widest, head Ø50.
    p = {{0, 0},    {0, 30},   {20, 36},  {45, 40},    {70, 41},  {95, 39},
         {120, 33}, {145, 24}, {165, 18}, {180, 17.5}, {195, 20}, {212, 24},
         {225, 25}, {238, 24}, {250, 20}, {260, 13},   {266, 6},  {268, 0}};
  } else if (name == "small-bottle") {
    // Ø52 × 80: body, short shoulder, neck and cap.
    p = {{0, 0}, {0, 24}, {2, 26}, {58, 26}, {66, 21}, {70, 12}, {80, 12}, {80, 0}};
  } else {
    throw std::invalid_argument("unknown object '" + name +
                                "' (sphere, water-bottle, bowling-pin, small-bottle)");
  }
  Check(p, name);
  return p;
}

LatheProfile ResampleProfile(const LatheProfile& profile, double max_step_mm) {
  if (!(max_step_mm > 0)) throw std::invalid_argument("max_step_mm must be positive");
  LatheProfile dense;
  for (size_t i = 0; i + 1 < profile.size(); ++i) {
    const auto [z0, r0] = profile[i];
    const auto [z1, r1] = profile[i + 1];
    const int steps =
        std::max(1, static_cast<int>(std::ceil(std::hypot(z1 - z0, r1 - r0) / max_step_mm)));
    for (int k = 0; k < steps; ++k) {
      dense.emplace_back(z0 + (z1 - z0) * k / steps, r0 + (r1 - r0) * k / steps);
    }
  }
  if (!profile.empty()) dense.push_back(profile.back());
  return dense;
}

LatheProfile ReadLatheProfile(const std::filesystem::path& path) {
  LatheProfile profile;
  for (const DataLine& line : ReadDataLines(path)) {
    const int number = line.number;
    std::istringstream fields(line.text);
    double z, r;
    std::string rest;
    if (!(fields >> z >> r) || (fields >> rest)) {
      throw InputError(path.string() + ": line " + std::to_string(number) +
                       " is not 'height radius'");
    }
    profile.emplace_back(z, r);
  }
  Check(profile, path.string());
  return profile;
}

TriangleMesh MakeLatheMesh(const LatheProfile& profile, int segments,
                           std::array<std::uint8_t, 3> rgb) {
  IHS_CHECK_ARG(segments >= 3, "lathe segments must be at least 3");
  Check(profile, "lathe profile");
  // Closed ends: a pole where the radius is zero, else a centre point making a flat disc.
  LatheProfile closed = profile;
  if (closed.front().second > 0) closed.insert(closed.begin(), {closed.front().first, 0.0});
  if (closed.back().second > 0) closed.emplace_back(closed.back().first, 0.0);
  // Drop repeated points, which would make degenerate faces.
  LatheProfile points;
  for (const auto& p : closed) {
    if (points.empty() || p != points.back()) points.push_back(p);
  }
  TriangleMesh mesh;
  std::vector<std::vector<std::int32_t>> rings;
  for (const auto& [z, r] : points) {
    std::vector<std::int32_t> ring;
    if (r == 0) {
      ring.assign(segments, static_cast<std::int32_t>(mesh.vertices.size()));
      mesh.vertices.emplace_back(0, 0, z);
    } else {
      for (int k = 0; k < segments; ++k) {
        const double phi = 2 * M_PI * k / segments;
        ring.push_back(static_cast<std::int32_t>(mesh.vertices.size()));
        mesh.vertices.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
      }
    }
    rings.push_back(ring);
  }
  for (size_t i = 0; i + 1 < rings.size(); ++i) {
    for (int k = 0; k < segments; ++k) {
      const int k1 = (k + 1) % segments;
      const std::int32_t a = rings[i][k], b = rings[i][k1], c = rings[i + 1][k1],
                         d = rings[i + 1][k];
      // Counter-clockwise seen from outside: upward along z, around counter-clockwise from +z.
      if (a != b) mesh.faces.push_back({a, b, c});
      if (c != d) mesh.faces.push_back({a, c, d});
    }
  }
  mesh.colors.assign(mesh.vertices.size(), rgb);
  mesh.ComputeVertexNormals();
  return mesh;
}

TriangleMesh MakeTexturedBox(const Eigen::Vector3d& size, double cell_mm) {
  IHS_CHECK_ARG(size.minCoeff() > 0, "box size must be positive");
  IHS_CHECK_ARG(cell_mm > 0, "box cell size must be positive");
  TriangleMesh mesh;
  const Eigen::Vector3d lo(-size.x() / 2, -size.y() / 2, 0),
      hi(size.x() / 2, size.y() / 2, size.z());
  static const std::array<std::uint8_t, 3> kHues[6] = {
      {200, 40, 40}, {40, 160, 40}, {40, 60, 200}, {210, 180, 30}, {160, 40, 160}, {30, 170, 170}};
  // Each face: a grid of quads with unshared vertices per cell, so colours stay crisp.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
      const int nu = std::max(1, static_cast<int>(std::ceil(size[u_axis] / cell_mm)));
      const int nv = std::max(1, static_cast<int>(std::ceil(size[v_axis] / cell_mm)));
      const int face_index = axis * 2 + side;
      for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
          const bool dark = (i + j) % 2 == 0;
          std::array<std::uint8_t, 3> color = kHues[face_index];
          if (dark) {
            for (auto& c : color) c = static_cast<std::uint8_t>(c / 3);
          }
          const auto base = static_cast<std::int32_t>(mesh.vertices.size());
          for (int corner = 0; corner < 4; ++corner) {
            Eigen::Vector3d p;
            p[axis] = side ? hi[axis] : lo[axis];
            p[u_axis] = lo[u_axis] + size[u_axis] * (i + (corner == 1 || corner == 2)) / nu;
            p[v_axis] = lo[v_axis] + size[v_axis] * (j + (corner >= 2)) / nv;
            mesh.vertices.push_back(p.cast<float>());
            mesh.colors.push_back(color);
          }
          // u × v points along +axis: keep that order on the high side, reverse it on the low.
          if (side) {
            mesh.faces.push_back({base, base + 1, base + 2});
            mesh.faces.push_back({base, base + 2, base + 3});
          } else {
            mesh.faces.push_back({base, base + 2, base + 1});
            mesh.faces.push_back({base, base + 3, base + 2});
          }
        }
      }
    }
  }
  mesh.ComputeVertexNormals();
  return mesh;
}

}  // namespace ihs::synth
