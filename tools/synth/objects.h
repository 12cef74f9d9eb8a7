#pragma once
// Objects of known shape for the synthetic benchmark: the paper's four as surfaces of
// revolution with its dimensions, any lathe profile given as (height, radius) pairs, and a
// textured box. Object frame: symmetry axis +z, base at z = 0, mm.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/triangle_mesh.h"

namespace ihs::synth {

/// A lathe profile: (height z, radius r) pairs from the bottom (z = 0) to the top, z
/// non-decreasing. A zero radius at either end closes the surface there; otherwise it is
/// closed with a flat disc.
using LatheProfile = std::vector<std::pair<double, double>>;

/// The paper's objects (Table 1): sphere Ø70; water bottle Ø73 × 218; bowling pin head Ø50,
/// body Ø82, height 268; small bottle Ø52 × 80.
LatheProfile PaperObjectProfile(const std::string& name);

/// Names accepted by PaperObjectProfile: "sphere", "water-bottle", "bowling-pin", "small-bottle".
std::vector<std::string> PaperObjectNames();

/// Reads "height radius" lines ('#' comments) from a file; throws ihs::InputError naming the
/// file and line when malformed (fewer than 2 points, negative radius, decreasing height).
LatheProfile ReadLatheProfile(const std::filesystem::path& path);

/// `profile` with points added along each segment, so that none is longer than `max_step_mm`
/// (the shape is unchanged; its mesh gets rings that dense).
LatheProfile ResampleProfile(const LatheProfile& profile, double max_step_mm);

/// Revolves `profile` about +z with `segments` around: a closed, outward mesh with normals and
/// a uniform colour `rgb`.
TriangleMesh MakeLatheMesh(const LatheProfile& profile, int segments,
                           std::array<std::uint8_t, 3> rgb = {235, 235, 235});

/// A closed box of `size` (x, y, z) mm standing on z = 0, centred on the axis, its faces
/// subdivided into cells of at most `cell_mm` with a colour pattern (a checkerboard with a hue
/// per face) so that visual features have something to find.
TriangleMesh MakeTexturedBox(const Eigen::Vector3d& size, double cell_mm = 5.0);

}  // namespace ihs::synth
