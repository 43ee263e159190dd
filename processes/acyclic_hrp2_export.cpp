// acyclic-hrp2-export: writes a trajectory as OpenHRP SequencePlayer files
// (BASENAME.pos, .waist, .zmp) at the controller period, after the same
// checks and with the same stabilizer schedule and references as the bridge.
// Exit: 0 written, 1 refused (a limit, a NaN, a jump: reason printed),
// 2 bad input (arguments, files).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <unistd.h>

#include "processes/command_line.h"
#include "hrp2_bridge/contract_check.h"
#include "hrp2_bridge/prepared_trajectory.h"
#include "hrp2_bridge/sequence_player.h"
#include "hrp2_bridge/trajectory_file.h"
#include "planner/common/format_error.h"

int main(int argc, char** argv) {
  using namespace acyclic;
  CLI::App app{
      "Exports a trajectory (acyclic.trajectory/1) to OpenHRP/hrpsys SequencePlayer files: BASENAME.pos\n"
      "(joint angles, controller order, rad), BASENAME.waist (base x y z roll pitch yaw, world) and\n"
      "BASENAME.zmp (ZMP in the waist frame), rows 't v1 ... vN' at the controller period. The trajectory\n"
      "is checked against the robot's joint position and velocity limits (refused, never clamped) and against\n"
      "the validity contract (every sample a valid posture with its contacts) first.\n"
      "Exit status: 0 written, 1 refused (reason printed), 2 bad input."};
  std::string in, out, scenario, config_path;
  double dt = 0;
  int zmp_stride = 10;
  app.add_option("--in", in, "trajectory file (acyclic.trajectory/1)")->required();
  app.add_option("--out", out, "basename of the files to write (BASENAME.pos, .waist, .zmp)")
      ->required()
      ->check(acyclic::proc::InWritableDirectory());
  app.add_option("--scenario", scenario, "scenario file (default: the one the trajectory names)");
  app.add_option("--config", config_path, "bridge configuration (acyclic.hrp2_bridge/1): dt, margins, stabilizer lead/lag");
  app.add_option("--dt", dt, "controller period, s (default: the configuration's, else 0.005)");
  bool no_contract = false;
  app.add_flag("--no-contract", no_contract, "skip the validity contract check (the limits are always checked)");
  app.add_option("--zmp-stride", zmp_stride, "quasi-static LP every N samples, interpolated between (default 10)")
      ->check(CLI::PositiveNumber);
  ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)

  hrp2::LoadedTrajectory lt;
  hrp2::BridgeConfig cfg;
  try {
    if (!config_path.empty()) cfg = hrp2::BridgeConfig::load(config_path);
    if (dt != 0) cfg.dt = dt;
    if (no_contract) cfg.check_contract = false;
    cfg.validate();
    lt = hrp2::loadTrajectoryFile(in, scenario);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-hrp2-export: %s\n", e.what());
    return 2;
  }
  hrp2::PrepareOptions opt;
  opt.zmp_stride = zmp_stride;
  // Progress on a terminal only (the contract check takes about 2 ms a sample).
  const bool tty = isatty(fileno(stderr));
  auto progress = [&](int done, int total) {
    if (tty) std::fprintf(stderr, "\racyclic-hrp2-export: checking the validity contract: %d / %d samples", done, total);
  };
  const hrp2::PrepareResult r = hrp2::prepareChecked(lt.trajectory, lt.scenario, cfg, opt, progress);
  if (tty && cfg.check_contract) std::fprintf(stderr, "\n");
  if (!r.check.ok) {
    std::fprintf(stderr, "acyclic-hrp2-export: %s: refused: %s\n", in.c_str(), r.check.reason.c_str());
    return 1;
  }
  try {
    hrp2::writeSequencePlayer(r.prepared, out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "acyclic-hrp2-export: %s\n", e.what());
    return 2;
  }
  const hrp2::PreparedTrajectory& p = r.prepared;
  std::printf("acyclic-hrp2-export: %s: %zu rows at %.3f s (%.3f s), %d joints -> %s.pos, %s.waist, %s.zmp\n",
              in.c_str(), p.samples.size(), p.dt, p.duration(), lt.scenario.robot->numJoints(), out.c_str(),
              out.c_str(), out.c_str());
  std::printf("acyclic-hrp2-export: ZMP from the feet's forces on %d rows, CoM projection on %zu (LP failures: %d)\n",
              p.zmp_from_forces, p.samples.size() - p.zmp_from_forces, p.zmp_lp_failures);
  for (const hrp2::StabilizerSwitch& s : p.switches)
    std::printf("acyclic-hrp2-export: stabilizer %s at t = %.3f s: %s\n", s.on ? "on" : "off", s.t, s.why.c_str());
  return 0;
}
