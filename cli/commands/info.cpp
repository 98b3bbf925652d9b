// hairvox info FILE [--json]: what a groom file holds.
#include "../commands.h"
#include <hairvox/core/format.h>

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

namespace hairvox::cli {

namespace {

struct InfoOptions {
    std::string input;
    bool json = false;
};

void runInfo(const InfoOptions& opt) {
    const LoadedGroom loaded = readGroom(opt.input);
    const Groom& groom = loaded.groom;
    const GroomStats st = computeStats(groom);
    std::vector<std::string> attributes;
    if (!groom.thickness.empty())
        attributes.emplace_back("thickness");
    if (!groom.transparency.empty())
        attributes.emplace_back("transparency");
    if (!groom.color.empty())
        attributes.emplace_back("color");

    std::vector<std::string> warnings = loaded.warnings;
    if (loaded.sanitized.droppedSegments > 0)
        warnings.push_back(strCat("dropped ", loaded.sanitized.droppedSegments,
                                  " zero-length segment(s)"));
    if (loaded.sanitized.droppedStrands > 0)
        warnings.push_back(strCat("dropped ", loaded.sanitized.droppedStrands,
                                  " strand(s) of coincident points"));
    if (groom.empty())
        warnings.emplace_back("the groom is empty");

    if (opt.json) {
        const Vec3f lo = st.bounds.empty() ? Vec3f(0.0f) : st.bounds.min;
        const Vec3f hi = st.bounds.empty() ? Vec3f(0.0f) : st.bounds.max;
        const nlohmann::json j = {
            {"file", opt.input},
            {"format", toString(loaded.format)},
            {"strands", st.strands},
            {"points", st.points},
            {"segments", st.segments},
            {"bounds", {{"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}}},
            {"total_length", st.totalLength},
            {"mean_segment_length", st.meanSegmentLength},
            {"attributes", attributes},
            {"warnings", warnings},
        };
        std::cout << j.dump(2) << "\n";
        return;
    }
    for (const std::string& w : warnings)
        std::fprintf(stderr, "hairvox: warning: %s: %s\n", opt.input.c_str(), w.c_str());
    const Vec3f size = st.bounds.extent();
    std::printf("file:                %s (%s)\n", opt.input.c_str(), toString(loaded.format));
    std::printf("strands:             %s\n", thousands(st.strands).c_str());
    std::printf("points:              %s\n", thousands(st.points).c_str());
    std::printf("segments:            %s\n", thousands(st.segments).c_str());
    if (!st.bounds.empty())
        std::printf("bounding box:        (%.6g, %.6g, %.6g) .. (%.6g, %.6g, %.6g), size %.6g x "
                    "%.6g x %.6g\n",
                    double(st.bounds.min.x), double(st.bounds.min.y), double(st.bounds.min.z),
                    double(st.bounds.max.x), double(st.bounds.max.y), double(st.bounds.max.z),
                    double(size.x), double(size.y), double(size.z));
    std::printf("total fiber length:  %.6g\n", st.totalLength);
    std::printf("mean segment length: %.6g (min %.6g, max %.6g)\n", st.meanSegmentLength,
                st.minSegmentLength, st.maxSegmentLength);
    std::printf("attributes:          %s\n",
                attributes.empty() ? "none" : join(attributes, ", ").c_str());
}

} // namespace

void addInfoCommand(CLI::App& app) {
    auto opt = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand("info", "Print what a groom file (.hair, .tfx, .obj) holds");
    cmd->add_option("file", opt->input, "Groom file")->required();
    cmd->add_flag("--json", opt->json, "Print JSON instead of text");
    cmd->callback([opt] { runInfo(*opt); });
}

} // namespace hairvox::cli
