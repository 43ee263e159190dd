#include "processes/supervisor.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace acyclic {

std::string executableDir() {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

pid_t Supervisor::spawn(const ChildSpec& spec) {
  if (access(spec.argv.at(0).c_str(), X_OK) != 0)
    throw std::runtime_error(spec.name + ": cannot execute " + spec.argv[0]);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(spec.name + ": fork failed: " + std::strerror(errno));
  if (pid == 0) {
    // Child: die with the launcher; output to its log; default signals.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    if (!spec.log_path.empty()) {
      const int fd = open(spec.log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
      if (fd >= 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
        close(fd);
      }
    }
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    std::vector<char*> args;
    for (const auto& a : spec.argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  log_("started " + spec.name + " (pid " + std::to_string(pid) + ")");
  return pid;
}

void Supervisor::start(const ChildSpec& spec) {
  // A fresh log for a fresh start; restarts append to it.
  if (!spec.log_path.empty()) std::fclose(std::fopen(spec.log_path.c_str(), "w"));
  Child c;
  c.spec = spec;
  c.pid = spawn(spec);
  children_.push_back(c);
}

std::vector<std::string> Supervisor::poll(std::vector<std::string>* gone) {
  std::vector<std::string> restarted;
  for (auto& c : children_) {
    if (c.pid <= 0) continue;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) != c.pid) continue;
    const std::string how = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                                : "exited with status " + std::to_string(WEXITSTATUS(status));
    c.pid = -1;
    if (c.spec.respawn && c.restarts < c.spec.max_restarts) {
      ++c.restarts;
      log_(c.spec.name + " " + how + ": restarting (" + std::to_string(c.restarts) + " of " +
           std::to_string(c.spec.max_restarts) + ")");
      c.pid = spawn(c.spec);
      restarted.push_back(c.spec.name);
    } else {
      const std::string what =
          c.spec.name + " " + how +
          (c.spec.respawn ? ": not restarted (" + std::to_string(c.restarts) + " restarts already)" : "");
      log_(what);
      if (gone) gone->push_back(what);
    }
  }
  return restarted;
}

void Supervisor::stopAll(double grace_s) {
  for (auto& c : children_)
    if (c.pid > 0) kill(c.pid, SIGTERM);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  for (auto& c : children_) {
    while (c.pid > 0) {
      int status = 0;
      const pid_t r = waitpid(c.pid, &status, WNOHANG);
      if (r == c.pid || r < 0) {
        c.pid = -1;
        break;
      }
      if (std::chrono::steady_clock::now() > deadline) {
        log_(c.spec.name + " did not stop within " + std::to_string(grace_s) + " s: killed");
        kill(c.pid, SIGKILL);
        waitpid(c.pid, &status, 0);
        c.pid = -1;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

pid_t Supervisor::pid(const std::string& name) const {
  for (const auto& c : children_)
    if (c.spec.name == name) return c.pid;
  return -1;
}

int Supervisor::restarts(const std::string& name) const {
  for (const auto& c : children_)
    if (c.spec.name == name) return c.restarts;
  return 0;
}

}  // namespace acyclic
