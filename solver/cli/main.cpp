// rcfd-solve: the solver's command line (docs/contracts.md). Every sub-command lives in its own file and
// registers itself through cli::addCommand; this file only parses and maps failures to exit codes.

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <iostream>
#include <map>
#include <memory>

#include "cli/Command.hpp"
#include "core/Errors.hpp"

namespace rcfd::cli {
namespace {
struct Registered {
  std::string description;
  Setup setup;
};
std::map<std::string, Registered>& commands() {
  static std::map<std::string, Registered> instance;
  return instance;
}
}  // namespace

bool addCommand(std::string name, std::string description, Setup setup) {
  commands().emplace(std::move(name), Registered{std::move(description), std::move(setup)});
  return true;
}
}  // namespace rcfd::cli

int main(int argc, char** argv) {
  using namespace rcfd;
  // stdout carries only machine-readable output (--progress-json lines, --json reports): logs go to stderr.
  spdlog::set_default_logger(spdlog::stderr_color_mt("rcfd"));
  CLI::App app{"rcfd-solve: recurrence CFD of spray coating in spouted beds"};
  app.require_subcommand(1);
  std::map<CLI::App*, cli::Action> actions;
  for (auto& [name, cmd] : cli::commands()) {
    CLI::App* sub = app.add_subcommand(name, cmd.description);
    actions[sub] = cmd.setup(*sub);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : exit_code::invalid_input;
  }
  try {
    for (auto& [sub, action] : actions) {
      if (sub->parsed()) return action();
    }
    return exit_code::invalid_input;
  } catch (const InputError& e) {
    std::cerr << "error: invalid input: " << e.what() << "\n";
    return exit_code::invalid_input;
  } catch (const Cancelled& e) {
    std::cerr << "cancelled: " << e.what() << "\n";
    return exit_code::cancelled;
  } catch (const RunError& e) {
    std::cerr << "error: run failed: " << e.what() << "\n";
    return exit_code::run_failed;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return exit_code::run_failed;
  }
}
