#include "fusion/turn_carry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/check.h"

namespace ihs::fusion {

void TurnCarryOptions::Check() const {
  IHS_CHECK_ARG(window_frames >= 2 && window_frames <= 1000,
                "fusion.turn_carry.window_frames must be in [2, 1000]");
  IHS_CHECK_ARG(recognise_deg > 0 && recognise_deg <= 360,
                "fusion.turn_carry.recognise_deg must be in (0, 360]");
  IHS_CHECK_ARG(min_consistency > 0 && min_consistency <= 1,
                "fusion.turn_carry.min_consistency must be in (0, 1]");
  IHS_CHECK_ARG(smoothing_frames >= 1 && smoothing_frames <= 100,
                "fusion.turn_carry.smoothing_frames must be in [1, 100]");
  IHS_CHECK_ARG(recognise_max_frame_deg > 0,
                "fusion.turn_carry.recognise_max_frame_deg must be > 0");
  IHS_CHECK_ARG(max_frame_turn_deg > 0 && max_frame_turn_deg <= 180,
                "fusion.turn_carry.max_frame_turn_deg must be in (0, 180]");
  IHS_CHECK_ARG(surface_frames >= 1 && surface_frames <= 1000,
                "fusion.turn_carry.surface_frames must be in [1, 1000]");
  IHS_CHECK_ARG(min_free_share >= 0 && min_free_share <= 1,
                "fusion.turn_carry.min_free_share must be in [0, 1]");
  IHS_CHECK_ARG(hand_weight >= 0 && hand_weight <= 1,
                "fusion.turn_carry.hand_weight must be in [0, 1]");
  IHS_CHECK_ARG(catch_up_frames >= 0 && catch_up_frames <= 10000,
                "fusion.turn_carry.catch_up_frames must be in [0, 10000]");
}

const char* ToString(HandTurn turn) {
  switch (turn) {
    case HandTurn::kUnknown:
      return "unknown";
    case HandTurn::kOn:
      return "on";
    case HandTurn::kBack:
      return "back";
    case HandTurn::kUndecided:
      return "undecided";
  }
  return "unknown";
}

TurnCarry::TurnCarry(TurnCarryOptions options) : options_((options.Check(), options)) {}

namespace {

// `value` appended to the last `frames` values (the oldest dropped), and their mean.
double PushedMean(std::deque<double>* recent, double value, int frames) {
  recent->push_back(value);
  while (static_cast<int>(recent->size()) > frames) recent->pop_front();
  return std::accumulate(recent->begin(), recent->end(), 0.0) / static_cast<double>(recent->size());
}

}  // namespace

HandTurn TurnCarry::Judge(const std::optional<Rigid3>& hand_motion, const Rigid3& cam_from_object) {
  turn_.reset();
  carried_rad_ = 0;
  const Eigen::AngleAxisd step(hand_motion ? hand_motion->rotation() : Eigen::Matrix3d::Identity());
  if (!hand_motion || step.angle() > options_.max_frame_turn_deg * M_PI / 180.0) {
    along_axis_.clear();
    const bool back = hand_motion && recognised_ && options_.fast_back_kept_out &&
                      (step.axis() * step.angle()).dot(cam_from_object.rotation() * axis_) < 0;
    return back ? HandTurn::kBack : HandTurn::kUnknown;
  }
  // The hand's turn in the object frame, where a turn about the object's own axis stays put.
  turn_ = cam_from_object.rotation().transpose() * (step.axis() * step.angle());
  if (!recognised_) return HandTurn::kUnknown;
  const double along = turn_->dot(axis_);
  const double mean = PushedMean(&along_axis_, along, options_.smoothing_frames);
  if (along > 0 && mean > 0) {
    carried_rad_ = along;
    // The axis follows the hand's turns on (their wobble about other axes averages out).
    turned_on_ += *turn_;
    axis_ = turned_on_.normalized();
    return HandTurn::kOn;
  }
  if (options_.undecided_to_contacts && !(along < 0 && mean < 0)) return HandTurn::kUndecided;
  return HandTurn::kBack;
}

void TurnCarry::Learn(bool contacts_used, bool registered) {
  if (recognised_ || !turn_) return;
  if (options_.catch_up_frames > 0) {
    history_.emplace_back(*turn_, registered);
    while (static_cast<int>(history_.size()) > options_.catch_up_frames) history_.pop_front();
  }
  if (!contacts_used) return;
  const double most = options_.recognise_max_frame_deg * M_PI / 180.0;
  contact_turns_.push_back(turn_->norm() > most ? Eigen::Vector3d(turn_->normalized() * most)
                                                : *turn_);
  while (static_cast<int>(contact_turns_.size()) > options_.window_frames) {
    contact_turns_.pop_front();
  }
  Recognise();
}

void TurnCarry::Recognise() {
  Eigen::Vector3d net = Eigen::Vector3d::Zero();
  double travelled = 0;
  for (const Eigen::Vector3d& turn : contact_turns_) {
    net += turn;
    travelled += turn.norm();
  }
  const double net_deg = net.norm() * 180.0 / M_PI;
  if (net_deg >= options_.recognise_deg && net.norm() >= options_.min_consistency * travelled) {
    recognised_ = true;
    axis_ = net.normalized();
    turned_on_ = net;
    contact_turns_.clear();
    catch_up_rad_ = MissedTurn();
    history_.clear();
  }
}

double TurnCarry::MissedTurn() const {
  // The frames judged as Judge would have, had the axis been known: on in the frame and on
  // average, and nothing registered them.
  std::deque<double> recent;
  double missed = 0;
  for (const auto& [turn, registered] : history_) {
    const double along = turn.dot(axis_);
    const double mean = PushedMean(&recent, along, options_.smoothing_frames);
    if (!registered && along > 0 && mean > 0) missed += along;
  }
  return missed;
}

double TurnCarry::TakeCatchUp() {
  const double catch_up = catch_up_rad_;
  catch_up_rad_ = 0;
  return catch_up;
}

void TurnCarry::ObserveSurface(int free_directions) {
  if (free_directions < 0) return;
  surface_free_.push_back(free_directions > 0);
  while (static_cast<int>(surface_free_.size()) > options_.surface_frames) {
    surface_free_.pop_front();
  }
}

bool TurnCarry::SurfaceLeavesTurnFree() const {
  if (surface_free_.empty()) return false;
  const auto free = std::count(surface_free_.begin(), surface_free_.end(), true);
  return free >= options_.min_free_share * static_cast<double>(surface_free_.size());
}

Rigid3 TurnCarry::Carry(const Rigid3& cam_from_object, const Eigen::Vector3d& pivot) const {
  return Turn(cam_from_object, pivot, carried_rad_);
}

Rigid3 TurnCarry::Turn(const Rigid3& cam_from_object, const Eigen::Vector3d& pivot,
                       double radians) const {
  const Eigen::Vector3d axis = cam_from_object.rotation() * axis_;
  const Rigid3 turn = Rigid3::Translation(pivot) * Rigid3::FromAxisAngle(axis, radians) *
                      Rigid3::Translation(-pivot);
  return turn * cam_from_object;
}

Rigid3 TurnCarry::Blend(const Rigid3& previous, const Rigid3& registered,
                        const Eigen::Vector3d& pivot, double* moved_rad) const {
  // The registered step's turn about the axis, where the previous pose put the axis.
  const Eigen::AngleAxisd step(registered.rotation() * previous.rotation().transpose());
  const double registered_rad = (step.axis() * step.angle()).dot(previous.rotation() * axis_);
  *moved_rad = options_.hand_weight * (carried_rad_ - registered_rad);
  return Turn(registered, pivot, *moved_rad);
}

}  // namespace ihs::fusion
