// hairvox: command-line entry point.
//
// Exit codes: 0 success, 1 internal error (a bug), 2 bad input or usage,
// 130 interrupted by the user.
#include "commands.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/version.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    CLI::App app{std::string("hairvox ") + hairvox::version() +
                 ": hair rendering with a voxel-grid dual-scattering global term"};
    app.set_version_flag("--version", std::string(hairvox::version()));
    app.require_subcommand(1, 1);
    hairvox::cli::addBenchCommand(app);
    hairvox::cli::addCompareCommand(app);
    hairvox::cli::addGenerateCommand(app);
    hairvox::cli::addInfoCommand(app);
    hairvox::cli::addProbeCommand(app);
    hairvox::cli::addRenderCommand(app);
    hairvox::cli::addSheetCommand(app);
    hairvox::cli::addStatusCommand(app);
    hairvox::cli::addSubmitCommand(app);
    hairvox::cli::addTablesCommand(app);
    hairvox::cli::addTransmittanceCommand(app);
    hairvox::cli::addVoxelizeCommand(app);
    hairvox::installInterruptHandler();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    } catch (const hairvox::InputError& e) {
        std::fprintf(stderr, "hairvox: error: %s\n", e.what());
        return 2;
    } catch (const hairvox::Interrupted& e) {
        std::fprintf(stderr, "hairvox: %s\n", e.what());
        return 130;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "hairvox: internal error: %s\n", e.what());
        return 1;
    }
    return 0;
}
