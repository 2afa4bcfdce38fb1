// mujoco_bare_loop: the cheapest loop that steps a MuJoCo cart-pole, to measure the MuJoCo sim and
// train_headless against (bench/run_benchmarks.sh (j) to (l)): MuJoCo's own API and nothing of this
// package. Each step sets the motor's ctrl from a bang-bang rule on the pole (push toward the lean,
// at full ctrl: the cheapest controller that keeps the states physical), then calls mj_step
// frame_skip times, as one tau of physics/tau = frame_skip timesteps; a state past the task's box
// (|x| > 2.4 m, |theta| > 0.21 rad) starts again from rest with mj_resetData, as an episode would.
// Prints one line "steps=N wall_s=T rate=R us_per_step=U" (steps of frame_skip mj_steps each).
//
// usage: mujoco_bare_loop MODEL.xml CART_JOINT POLE_JOINT ACTUATOR FRAME_SKIP [DURATION_S]
#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv)
{
  if (argc < 6)
  {
    std::fprintf(stderr, "usage: mujoco_bare_loop MODEL.xml CART_JOINT POLE_JOINT ACTUATOR FRAME_SKIP [DURATION_S]\n");
    return 2;
  }
  const int frame_skip = std::atoi(argv[5]);
  const double duration = argc > 6 ? std::atof(argv[6]) : 2.0;
  char error[1000] = "";
  mjModel* m = mj_loadXML(argv[1], nullptr, error, sizeof error);
  if (m == nullptr)
  {
    std::fprintf(stderr, "mujoco_bare_loop: %s: %s\n", argv[1], error);
    return 1;
  }
  const int cart = mj_name2id(m, mjOBJ_JOINT, argv[2]);
  const int pole = mj_name2id(m, mjOBJ_JOINT, argv[3]);
  const int motor = mj_name2id(m, mjOBJ_ACTUATOR, argv[4]);
  if (cart < 0 || pole < 0 || motor < 0 || frame_skip < 1)
  {
    std::fprintf(stderr, "mujoco_bare_loop: no joint %s, joint %s or actuator %s in %s, or FRAME_SKIP < 1\n", argv[2],
                 argv[3], argv[4], argv[1]);
    return 1;
  }
  mjData* d = mj_makeData(m);
  const int x = m->jnt_qposadr[cart];
  const int theta = m->jnt_qposadr[pole];
  const int theta_dot = m->jnt_dofadr[pole];
  const double full = m->actuator_ctrlrange[2 * motor + 1];
  d->qpos[theta] = 0.03;
  mj_forward(m, d);

  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const Clock::time_point end =
      start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(duration));
  long steps = 0;
  // The clock is read every 1024 steps: a read costs about as much as a step.
  while ((steps & 1023) != 0 || Clock::now() < end)
  {
    d->ctrl[motor] = d->qpos[theta] + 0.1 * d->qvel[theta_dot] > 0.0 ? full : -full;
    for (int i = 0; i < frame_skip; ++i)
      mj_step(m, d);
    ++steps;
    if (!(std::abs(d->qpos[x]) < 2.4 && std::abs(d->qpos[theta]) < 0.21))
    {
      mj_resetData(m, d);
      d->qpos[theta] = 0.03;
      mj_forward(m, d);
    }
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("steps=%ld wall_s=%.6f rate=%.1f us_per_step=%.4f\n", steps, wall, steps / wall, 1e6 * wall / steps);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
