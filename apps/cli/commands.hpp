// Subcommands beyond run/check/resume live in their own files (apps/cli/cmd_*.cpp) and register
// themselves here, so adding one never touches main.cpp:
//
//   static const bool registered = ff::cli::register_command({"sweep", [](CLI::App& app) {
//     auto* sub = app.add_subcommand("sweep", "...");
//     ... add options bound to static/heap state ...
//     return ff::cli::Command::Run([=] { return 0; });  // called when `sub` was chosen
//   }});
#pragma once
#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace ff::cli {

struct Command {
  using Run = std::function<int()>;  // exit status; may throw ff::InputError / ff::Error
  std::string name;                  // the subcommand's name, as passed to add_subcommand
  std::function<Run(CLI::App&)> setup;
};

inline std::vector<Command>& registered_commands() {
  static std::vector<Command> commands;
  return commands;
}
inline bool register_command(Command c) {
  registered_commands().push_back(std::move(c));
  return true;
}

}  // namespace ff::cli
