#pragma once
/// \file Command.hpp
/// Sub-commands of rcfd-solve register themselves, one file each (validate, geometry, run, ...):
///
///   static const bool registered = rcfd::cli::addCommand(
///       "validate", "check a scene or job file", [](CLI::App& app) {
///         auto file = std::make_shared<std::string>();
///         app.add_option("FILE", *file)->required();
///         return [file] { ...; return rcfd::exit_code::success; };
///       });
///
/// The setup function adds the sub-command's options and returns the action run after parsing.
/// Actions report failure by throwing rcfd::InputError (exit 2), rcfd::RunError (3) or
/// rcfd::Cancelled (130); main() turns them into messages and exit codes.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace rcfd::cli {

using Action = std::function<int()>;
using Setup = std::function<Action(CLI::App&)>;

bool addCommand(std::string name, std::string description, Setup setup);

}  // namespace rcfd::cli
