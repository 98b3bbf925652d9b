// hairvox generate straight|wavy|curly -o FILE.hair [--strands N] [--points-per-strand M] [--seed
// S]
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <iostream>
#include <memory>

namespace hairvox::cli {

namespace {

struct GenerateOptions {
    std::string style;
    std::string output;
    ProceduralGroomParams params;
};

void runGenerate(const GenerateOptions& opt) {
    ProceduralGroomParams params = opt.params;
    params.style = *kGroomStyleNames.parse(opt.style); // CLI11 checked the choice
    params.validate();
    // The points, their copy in the file's encoding and the strand index:
    // refused before anything is allocated if that is beyond the machine.
    const std::uint64_t bytes =
        std::uint64_t(params.strands) * params.resolvedPointsPerStrand() * 2 * sizeof(Vec3f);
    if (bytes > defaultMemoryLimit())
        throw InputError(strCat("--strands ", params.strands, " × --points-per-strand ",
                                params.resolvedPointsPerStrand(), " needs ~", bytes >> 20,
                                " MiB, more than the ", defaultMemoryLimit() >> 20,
                                " MiB this machine allows (3/4 of its memory)"));
    const Groom groom = generateGroom(params);
    writeHairFile(opt.output, groom, strCat("hairvox generate ", opt.style));
    std::cout << "wrote " << opt.output << ": " << thousands(groom.strandCount()) << " "
              << opt.style << " strands, " << thousands(groom.pointCount()) << " points\n";
}

} // namespace

void addGenerateCommand(CLI::App& app) {
    auto opt = std::make_shared<GenerateOptions>();
    CLI::App* cmd = app.add_subcommand("generate", "Generate a procedural groom on a head sphere");
    cmd->add_option("style", opt->style, "Hair style")
        ->required()
        ->check(CLI::IsMember(kGroomStyleNames.names()));
    cmd->add_option("-o,--output", opt->output, "Output .hair file")->required();
    cmd->add_option("--strands", opt->params.strands, "Number of strands")
        ->capture_default_str()
        ->check(CLI::Range(1u, 10'000'000u));
    cmd->add_option("--points-per-strand", opt->params.pointsPerStrand,
                    "Points per strand (default: 32, curly 64)")
        ->check(CLI::Range(2u, 4096u));
    cmd->add_option("--seed", opt->params.seed, "Random seed")->capture_default_str();
    cmd->add_option("--length", opt->params.length, "Mean fiber length (m)")
        ->capture_default_str()
        ->check(CLI::Range(1e-4f, 1e3f));
    cmd->callback([opt] { runGenerate(*opt); });
}

} // namespace hairvox::cli
