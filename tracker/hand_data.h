#pragma once
// Loaders for the real hand data of the paper's scanning sessions (../shared/data/hand-iccv15:
// OFF mesh, SKIN weights, LIMITS, per-session SKEL and MOTION; formats in its README).

#include <filesystem>
#include <string>
#include <vector>

#include "core/rigid3.h"
#include "tracker/hand_model.h"

namespace ihs::tracker {

/// A hand model with the motion recorded in one scanning session.
struct RecordedHand {
  HandModel model;
  /// cam_from_bone per video frame (frame k is MOTION row k + 1), one transform per bone.
  std::vector<std::vector<Rigid3>> cam_from_bone;
};

/// Loads the model in `data_dir`/model and the session in `sequence_dir` (holding
/// Model_Hand_R.SKEL and Model_Hand_R.MOTION). The rest transforms come from MOTION row 0.
/// Throws ihs::InputError naming the file and line for anything missing or malformed.
RecordedHand LoadRecordedHand(const std::filesystem::path& data_dir,
                              const std::filesystem::path& sequence_dir);

/// The hand model of a data folder alone: its skeleton and rest transforms come from the first
/// session under `data_dir`/sequences (they are the same in every session). Throws
/// ihs::InputError when the folder holds no session.
HandModel LoadHandModel(const std::filesystem::path& data_dir);

/// The tracker's template: "procedural" (the project's own hand, MakeProceduralHand, built as a
/// right or a left hand) or a data folder holding a scanned hand (LoadHandModel). Throws
/// ihs::InputError when a scanned hand is not of the side asked for.
HandModel LoadHandTemplate(const std::string& name, bool right_hand = true);

/// Reads an OFF triangle mesh (3-vertex faces; larger polygons are fanned).
TriangleMesh ReadOffMesh(const std::filesystem::path& path);

}  // namespace ihs::tracker
