// No output may overwrite an input (issue 19, item 1): every command names its input files and
// the files it will write, and require_outputs_distinct() compares them before any work.
#include <fmt/format.h>
#include <fnmatch.h>
#include <sys/stat.h>

#include <filesystem>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "gmasim/errors.hpp"
#include "gmasim/io/io.hpp"
#include "gmasim/model/validate.hpp"

namespace gmasim {
namespace {

namespace fs = std::filesystem;

// What identifies a file: its device and inode when it exists (a hard link, a symbolic link or
// another spelling of the path is the same file), and always its absolute path with the
// symbolic links of its existing part resolved.
struct FileId {
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
  std::string canonical;
  bool pattern = false;  // the file name holds '*' (an output family: DIR/sweep_*.csv)
};

std::string canonical_of(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  const fs::path canon = fs::weakly_canonical(abs, ec);
  return (ec ? abs.lexically_normal() : canon).string();
}

// fnmatch's special characters in a literal part of a pattern.
std::string escaped(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '*' || c == '?' || c == '[' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

FileId identify(const std::string& path) {
  FileId id;
  const fs::path p(path);
  const std::string name = p.filename().string();
  id.pattern = name.find('*') != std::string::npos;
  id.canonical =
      id.pattern
          ? escaped(canonical_of(p.parent_path().empty() ? "." : p.parent_path())) + "/" + name
          : canonical_of(p);
  struct stat st {};
  if (!id.pattern && ::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
  }
  return id;
}

bool same_file(const FileId& out, const FileId& in) {
  if (out.pattern) {
    if (in.pattern) return false;
    return ::fnmatch(out.canonical.c_str(), in.canonical.c_str(), FNM_PATHNAME) == 0;
  }
  if (in.pattern) return ::fnmatch(in.canonical.c_str(), out.canonical.c_str(), FNM_PATHNAME) == 0;
  if (out.exists && in.exists) return out.dev == in.dev && out.ino == in.ino;
  return out.canonical == in.canonical;
}

bool allowed_pair(const std::vector<std::pair<std::string, std::string>>& allowed,
                  const std::string& a, const std::string& b) {
  for (const auto& [x, y] : allowed)
    if ((x == a && y == b) || (x == b && y == a)) return true;
  return false;
}

std::string shown(const FileArg& f) { return clip_for_message(f.path); }

}  // namespace

void require_outputs_distinct(const std::vector<FileArg>& inputs,
                              const std::vector<FileArg>& outputs,
                              const std::vector<std::pair<std::string, std::string>>& allowed) {
  std::vector<FileId> in_ids, out_ids;
  for (const auto& f : inputs) in_ids.push_back(identify(f.path));
  for (const auto& f : outputs) out_ids.push_back(identify(f.path));
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (inputs[i].path.empty() || !same_file(out_ids[o], in_ids[i])) continue;
      if (allowed_pair(allowed, inputs[i].flag, outputs[o].flag)) continue;
      throw InputError(fmt::format(
          "{} {}: would overwrite the input {} {}{}; an output never replaces an input: choose "
          "another {}",
          outputs[o].flag, shown(outputs[o]), inputs[i].flag, shown(inputs[i]),
          out_ids[o].pattern ? fmt::format(" (it writes {})", out_ids[o].canonical) : "",
          outputs[o].flag));
    }
    for (std::size_t p = 0; p < o; ++p) {
      if (outputs[p].flag == outputs[o].flag) continue;  // one flag's own family of files
      if (!same_file(out_ids[o], out_ids[p])) continue;
      throw InputError(fmt::format(
          "{} {}: the same file as {} {}; two outputs of one run cannot share a "
          "file: choose another {}",
          outputs[o].flag, shown(outputs[o]), outputs[p].flag, shown(outputs[p]), outputs[o].flag));
    }
  }
}

std::vector<FileArg> files_in(const std::string& dir, const std::vector<std::string>& names,
                              const std::string& flag) {
  std::vector<FileArg> out;
  for (const auto& n : names) out.push_back({(fs::path(dir) / n).string(), flag});
  return out;
}

}  // namespace gmasim
