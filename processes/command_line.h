#pragma once
// Every process's command line: a bad option or value is bad input, exit
// status 2 as for the process's other bad input (a scenario's bad field, a
// missing file), with CLI11's message naming the option; --help exits 0.
// (CLI11_PARSE would exit with CLI11's own codes, 104-114.)
#include <unistd.h>

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#define ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)  \
  try {                                              \
    (app).parse((argc), (argv));                     \
  } catch (const CLI::ParseError& e) {               \
    return (app).exit(e) == 0 ? 0 : 2;               \
  }

namespace acyclic::proc {

// For an option naming a file to write: its directory must exist and be
// writable when the command line is read, so that a bad path is bad input
// at once (exit 2, the option and the directory named) rather than a
// failure to write after the work (a search of minutes lost).
inline CLI::Validator InWritableDirectory() {
  return CLI::Validator(
      [](std::string& path) -> std::string {
        std::filesystem::path dir = std::filesystem::path(path).parent_path();
        if (dir.empty()) dir = ".";
        std::error_code ec;
        if (!std::filesystem::is_directory(dir, ec)) return "directory " + dir.string() + " does not exist";
        if (access(dir.c_str(), W_OK) != 0) return "directory " + dir.string() + " is not writable";
        return std::string();
      },
      "PATH");
}

}  // namespace acyclic::proc
