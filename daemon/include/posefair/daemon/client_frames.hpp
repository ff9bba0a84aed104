#pragma once
// Frames, stated once: how a posefair pose reads in each client's frame (docs/outputs.md, "Frames").
//
// posefair's frame (the source of every mapping): right-handed, as in ROS REP 103. A body's
// x points forward, y left, z up; the world is the stream's own, z up (east-north-up for
// devices that know north). The quaternion rotates body coordinates into world coordinates,
// v_world = q v_body q*. So a turn to the left is a positive rotation about z, and a pitch up
// (nose up) a negative rotation about y.
//
// Each client's frame is this one seen through a fixed change of axes; the functions below are
// the only place an encoding learns it. Per-stream corrections (a tracker mounted crooked, a
// world turned) come first (StreamFrame), then the client's mapping.
#include <array>

#include "posefair/core/so3.hpp"

namespace posefair::daemon {

// A stream's corrections ([[stream]] mounting and world, docs/config.md), applied to every
// pose before any encoding: q_out = world · q · mounting, p_out = world · p. `mounting`
// rotates the body's axes into the sensor's (the inverse of how the sensor sits on the body);
// `world` rotates the stream's world into the world the clients should see.
struct StreamFrame {
  Quat mounting = Quat::Identity();
  Quat world = Quat::Identity();
  bool identity() const { return mounting.isApprox(Quat::Identity(), 0.0) && world.isApprox(Quat::Identity(), 0.0); }
  Quat orientation(const Quat& q) const { return world * q * mounting; }
  Vec3 position(const Vec3& p) const { return world * p; }
};

// A rotation from yaw, pitch, roll in degrees about posefair's z, y, x, composed
// R = Rz(yaw) · Ry(pitch) · Rx(roll) (right-handed: positive pitch is nose DOWN, as in REP 103).
Quat rotation_from_zyx_degrees(double yaw, double pitch, double roll);

// --- Unity (VMC, VRChat): left-handed, x right, y up, z forward, metres. ---
Vec3 unity_position(const Vec3& p);
// The same physical rotation in Unity's numbers (x, y, z, w as Unity's Quaternion holds them).
Quat unity_rotation(const Quat& q);
// Unity's Euler angles of a Unity rotation, degrees {x, y, z}, each in [-180, 180]:
// Quaternion.Euler(x, y, z) applies z first, then x, then y (R = Ry · Rx · Rz).
std::array<double, 3> unity_euler_zxy(const Quat& unity_q);

// --- Head-tracking angles (opentrack, FreeD), degrees. ---
// yaw: positive turning left (about up); pitch: positive looking up; roll: positive leaning
// right (clockwise as seen from behind). The body turns by yaw, then pitches, then rolls.
struct HeadAngles {
  double yaw = 0.0, pitch = 0.0, roll = 0.0;
};
HeadAngles head_angles(const Quat& q);

// --- opentrack "UDP over network": x right, y up, z back, centimetres. ---
Vec3 opentrack_position_cm(const Vec3& p);

}  // namespace posefair::daemon
