#pragma once
// Starts child processes, restarts those that die (like procman's
// auto-respawn), and stops them all: SIGTERM, a grace period, then SIGKILL.
// Children also get SIGTERM if the launcher itself dies (PR_SET_PDEATHSIG).
#include <sys/types.h>

#include <functional>
#include <string>
#include <vector>

namespace acyclic {

// The folder of the running executable (where its sibling executables are), "." if unknown.
std::string executableDir();

struct ChildSpec {
  std::string name;               // for logs
  std::vector<std::string> argv;  // argv[0] is the executable's path
  std::string log_path;           // stdout and stderr appended here; empty: inherited
  bool respawn = true;
  int max_restarts = 3;
};

class Supervisor {
 public:
  using Log = std::function<void(const std::string&)>;
  explicit Supervisor(Log log) : log_(std::move(log)) {}
  ~Supervisor() { stopAll(); }
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;

  // Starts a child; throws std::runtime_error if it cannot be started.
  void start(const ChildSpec& spec);
  // Reaps children that exited; restarts those allowed to. Returns the names
  // restarted by this call; the children that exited and will not be
  // restarted (too many restarts, or not to be respawned) are appended to
  // `gone` with how they ended ("name killed by signal 6: not restarted ...").
  std::vector<std::string> poll(std::vector<std::string>* gone = nullptr);
  void stopAll(double grace_s = 3.0);

  pid_t pid(const std::string& name) const;   // -1 if not running
  int restarts(const std::string& name) const;
  bool running(const std::string& name) const { return pid(name) > 0; }

 private:
  struct Child {
    ChildSpec spec;
    pid_t pid = -1;
    int restarts = 0;
  };
  pid_t spawn(const ChildSpec& spec);
  Log log_;
  std::vector<Child> children_;
};

}  // namespace acyclic
