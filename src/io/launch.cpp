// Running the Python package from C++ (figures): posix_spawnp, no shell (gmasim/io/io.hpp).
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "gmasim/io/io.hpp"

namespace gmasim {

std::string PythonCommand::text() const {
  std::string t = python + " -m " + module;
  for (const auto& a : args) t += " " + a;
  return t;
}

bool python_runnable(const std::string& python) {
  auto ok = [](const std::string& f) {
    std::error_code ec;
    return std::filesystem::is_regular_file(f, ec) && ::access(f.c_str(), X_OK) == 0;
  };
  if (python.find('/') != std::string::npos) return ok(python);
  const char* path = std::getenv("PATH");
  const std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t b = 0; b <= dirs.size();) {
    const std::size_t e = std::min(dirs.find(':', b), dirs.size());
    const std::string d = dirs.substr(b, e - b);
    if (ok((d.empty() ? std::string(".") : d) + "/" + python)) return true;
    b = e + 1;
  }
  return false;
}

int run_python(const PythonCommand& c) {
  // The child's environment: ours, with PYTHONPATH (when given) and MPLBACKEND replaced.
  std::vector<std::string> env = {"MPLBACKEND=Agg"};
  if (!c.python_path.empty()) {
    std::string path = c.python_path;
    if (const char* old = std::getenv("PYTHONPATH"); old != nullptr && *old != '\0')
      path += std::string(":") + old;
    env.push_back("PYTHONPATH=" + path);
  }
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string_view v(*e);
    if (v.starts_with("MPLBACKEND=") || (!c.python_path.empty() && v.starts_with("PYTHONPATH=")))
      continue;
    env.emplace_back(v);
  }
  std::vector<std::string> args = {c.python, "-m", c.module};
  args.insert(args.end(), c.args.begin(), c.args.end());
  auto pointers = [](std::vector<std::string>& strings) {
    std::vector<char*> p;
    for (auto& s : strings) p.push_back(s.data());
    p.push_back(nullptr);
    return p;
  };
  std::vector<char*> argv = pointers(args), envp = pointers(env);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (c.stdout_to_stderr) posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  pid_t pid = 0;
  const int spawned =
      posix_spawnp(&pid, c.python.c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : 127;
}

}  // namespace gmasim
