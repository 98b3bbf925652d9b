// hairvox CLI: one registration function per subcommand.
#pragma once

#include <CLI/CLI.hpp>

namespace hairvox::cli {

void addBenchCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addGenerateCommand(CLI::App& app);
void addInfoCommand(CLI::App& app);
void addProbeCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addSheetCommand(CLI::App& app);
void addStatusCommand(CLI::App& app);
void addSubmitCommand(CLI::App& app);
void addTablesCommand(CLI::App& app);
void addTransmittanceCommand(CLI::App& app);
void addVoxelizeCommand(CLI::App& app);

} // namespace hairvox::cli
