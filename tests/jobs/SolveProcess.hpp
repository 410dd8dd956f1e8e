#pragma once
/// \file SolveProcess.hpp
/// Runs the real rcfd-solve binary of this build with arguments and captures its stdout (optionally
/// with stderr) and exit code: the job tests drive the solver as users and the server do.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace rcfd::test {

inline const std::string kSolver = std::string(RCFD_BINARY_DIR) + "/rcfd-solve";

struct SolveResult {
  int exitCode = -1;
  std::string out;
};

inline SolveResult solve(const std::string& args, bool withStderr = false) {
  SolveResult r;
  FILE* pipe = popen((kSolver + " " + args + (withStderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) r.out += buffer;
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace rcfd::test
