// A robot state message read off a simulated task, as masa_sim_robot publishes it (a floating base
// named "trunk": the A1's), for the deploy runner's tests.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>

#include "common/sim/task.hpp"
#include "masa/lcmt_robot_state.hpp"

namespace masa::test {

// A robot state message read off a simulated task, as masa_sim_robot publishes it.
inline masa::lcmt_robot_state stateOf(const task::Task& t, int64_t utime) {
  const mjModel* m = t.model();
  const mjData* d = t.data();
  masa::lcmt_robot_state s{};
  s.utime = utime;
  s.num_joints = t.actDim();
  for (int k = 0; k < t.actDim(); ++k) {
    const int j = t.jointOfAction(k);
    s.joint_position.push_back(d->qpos[m->jnt_qposadr[j]]);
    s.joint_velocity.push_back(d->qvel[m->jnt_dofadr[j]]);
    s.joint_torque.push_back(0.0);
  }
  const int fj = mj_name2id(m, mjOBJ_JOINT, "trunk");
  const double* q = d->qpos + m->jnt_qposadr[fj];
  const double* v = d->qvel + m->jnt_dofadr[fj];
  s.has_base = true;
  s.base_x = q[0], s.base_y = q[1], s.base_z = q[2];
  s.base_qw = q[3], s.base_qx = q[4], s.base_qy = q[5], s.base_qz = q[6];
  s.base_vx = v[0], s.base_vy = v[1], s.base_vz = v[2];
  s.base_wx = v[3], s.base_wy = v[4], s.base_wz = v[5];
  return s;
}

}  // namespace masa::test
