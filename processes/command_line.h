#pragma once
// Every process's command line: a bad option or value is bad input, exit
// status 2 as for the process's other bad input (a scenario's bad field, a
// missing file), with CLI11's message naming the option; --help exits 0.
// (CLI11_PARSE would exit with CLI11's own codes, 104-114.)
#include <CLI/CLI.hpp>

#define ACYCLIC_PARSE_COMMAND_LINE(app, argc, argv)  \
  try {                                              \
    (app).parse((argc), (argv));                     \
  } catch (const CLI::ParseError& e) {               \
    return (app).exit(e) == 0 ? 0 : 2;               \
  }
