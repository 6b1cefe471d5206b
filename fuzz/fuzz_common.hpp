// Shared by the libFuzzer harnesses (scripts/fuzz.sh, docs/reliability.md): an input is
// either accepted or refused with gmasim::InputError; anything else (another exception, a
// crash, a sanitizer report, a hang) is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "gmasim/errors.hpp"

namespace gmasim_fuzz {

inline std::string as_text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// The loaders that read files get the input through a per-process file in /dev/shm (or
// /tmp), rewritten on every call.
inline std::string write_input(const std::uint8_t* data, std::size_t size, const char* ext) {
  static const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
  const std::string path =
      dir + "/gmasim_fuzz_" + std::to_string(static_cast<long>(getpid())) + ext;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) __builtin_trap();
  if (size > 0 && std::fwrite(data, 1, size, f) != size) __builtin_trap();
  std::fclose(f);
  return path;
}

// Runs f; an InputError (a clear refusal) is the expected outcome for bad input.
template <class F>
int accept_or_refuse(F&& f) {
  try {
    f();
  } catch (const gmasim::InputError&) {
  }
  return 0;
}

}  // namespace gmasim_fuzz
