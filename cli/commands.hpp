#pragma once
// The commands of the `cmc33` executable. A command is one file (cli/cmd_<name>.cpp) defining
// add_<name>(app): it adds its subcommand, options and help, and sets the callback that runs it.
// To add a command: write the file, declare its add_ function here and list it in kCommands.

#include <CLI/CLI.hpp>

namespace cmc33::cli {

void add_extract(CLI::App& app);
void add_info(CLI::App& app);
void add_topo(CLI::App& app);
void add_cell(CLI::App& app);
void add_verify(CLI::App& app);
void add_dataset(CLI::App& app);
void add_sweep(CLI::App& app);
void add_simplify(CLI::App& app);
void add_labels(CLI::App& app);

using AddCommand = void (*)(CLI::App&);

/// Every command, in the order `cmc33 --help` lists them.
inline constexpr AddCommand kCommands[] = {add_extract, add_info, add_topo, add_cell, add_verify, add_dataset, add_sweep, add_simplify, add_labels};

} // namespace cmc33::cli
