#include "process.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/shots/slurm.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <sys/stat.h>

namespace hairvox::shots {

namespace fs = std::filesystem;
using detail::shellQuoted;

void SubmitOptions::validate() const {
    if (perTask < 1 || perTask > 100000)
        throw InputError(
            strCat("--per-task ", perTask, ": expected frames per task in [1, 100000]"));
    if (cpus < 1 || cpus > 4096)
        throw InputError(strCat("--cpus ", cpus, ": expected CPUs per task in [1, 4096]"));
    // Slurm's time formats: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS.
    static const std::regex time(R"(^(\d+-)?\d+(:\d{1,2}){0,2}$)");
    if (!timeLimit.empty() && !std::regex_match(timeLimit, time))
        throw InputError(
            strCat("--time ", timeLimit,
                   ": expected Slurm's form [days-]hours:minutes:seconds, e.g. 02:00:00"));
    static const std::regex name(R"(^[A-Za-z0-9_.,-]+$)");
    if (!partition.empty() && !std::regex_match(partition, name))
        throw InputError(strCat("--partition ", partition,
                                ": expected a partition name (letters, digits, '_', '-', '.', "
                                "',' between several)"));
    static const std::regex mem(R"(^\d+[KMGT]?$)");
    if (!memory.empty() && !std::regex_match(memory, mem))
        throw InputError(strCat("--mem ", memory, ": expected Slurm's form, e.g. 8G or 8000M"));
    for (const std::string& option : sbatchOptions)
        if (option.size() < 2 || option[0] != '-' ||
            option.find_first_of("\n\r") != std::string::npos)
            throw InputError(
                strCat("--sbatch '", option, "': expected one sbatch option, e.g. --account=show"));
    for (const fs::path* p : {&shotFile, &workDir, &farmDir, &cacheDir, &hairvox})
        if (!p->is_absolute())
            throw std::invalid_argument(strCat("SubmitOptions: ", p->string(), " is not absolute"));
}

FarmJob makeFarmJob(const SubmitOptions& o, const FrameSet& frames, const FrameSet& shown) {
    o.validate();
    if (frames.empty())
        throw std::invalid_argument("makeFarmJob: no frames");
    FarmJob job;
    const std::string stem = o.shotFile.stem().string();
    job.script = o.farmDir / (stem + ".sbatch");
    job.logDir = o.farmDir / "logs";
    job.chunks = frames.chunks(o.perTask);
    const std::string quotedShot = shellQuoted(o.shotFile.string());

    std::string s;
    s += "#!/bin/bash\n";
    s += strCat("# Written by hairvox submit: ", o.shotFile.string(), ", frames ",
                frames.toString(), " (", frames.size(), ") in ", job.chunks.size(),
                " array tasks of up to ", o.perTask, ".\n");
    s += "# Each task renders its chunk of frames; a frame already done (its EXR\n"
         "# records this frame's digest) is skipped, so resubmitting is safe.\n";
    s += strCat("#SBATCH --job-name=", shellQuoted(strCat("hairvox-", stem)), "\n");
    s += strCat("#SBATCH --array=0-", job.chunks.size() - 1,
                o.maxRunning > 0 ? strCat("%", o.maxRunning) : std::string(), "\n");
    s += strCat("#SBATCH --cpus-per-task=", o.cpus, "\n");
    s += "#SBATCH --ntasks=1\n";
    s += strCat("#SBATCH --chdir=", o.workDir.string(), "\n");
    s += strCat("#SBATCH --output=", (job.logDir / (stem + "-%A_%a.out")).string(), "\n");
    s += strCat("#SBATCH --error=", (job.logDir / (stem + "-%A_%a.err")).string(), "\n");
    if (!o.partition.empty())
        s += strCat("#SBATCH --partition=", o.partition, "\n");
    if (!o.timeLimit.empty())
        s += strCat("#SBATCH --time=", o.timeLimit, "\n");
    if (!o.memory.empty())
        s += strCat("#SBATCH --mem=", o.memory, "\n");
    for (const std::string& option : o.sbatchOptions)
        s += strCat("#SBATCH ", option, "\n");
    s += "set -euo pipefail\n";
    s += "chunks=(";
    for (const FrameSet& c : job.chunks)
        s += strCat("\n  ", shellQuoted(c.toString()));
    s += "\n)\n";
    s += "frames=${chunks[$SLURM_ARRAY_TASK_ID]}\n";
    s += "echo \"hairvox task $SLURM_ARRAY_TASK_ID of job $SLURM_ARRAY_JOB_ID on $(hostname): "
         "frames $frames\"\n";
    s += strCat("exec ", shellQuoted(o.hairvox.string()), " render ", quotedShot,
                " --frames \"$frames\" --threads \"${SLURM_CPUS_PER_TASK:-", o.cpus, "}\" --cache ",
                shellQuoted(o.cacheDir.string()));
    if (o.force)
        s += " --force";
    for (const std::string& a : o.renderArgs)
        s += " " + shellQuoted(a);
    s += "\n";
    job.text = std::move(s);

    if (o.sheet) {
        job.sheetScript = o.farmDir / (stem + ".sheet.sbatch");
        std::string t;
        t += "#!/bin/bash\n";
        t += strCat("# Written by hairvox submit: the movie and contact sheet of ",
                    o.shotFile.string(), ",\n# run once every task of the render job succeeded.\n");
        t += strCat("#SBATCH --job-name=", shellQuoted(strCat("hairvox-", stem, "-sheet")), "\n");
        t += "#SBATCH --cpus-per-task=1\n#SBATCH --ntasks=1\n";
        t += strCat("#SBATCH --chdir=", o.workDir.string(), "\n");
        t += strCat("#SBATCH --output=", (job.logDir / (stem + "-sheet-%j.out")).string(), "\n");
        t += strCat("#SBATCH --error=", (job.logDir / (stem + "-sheet-%j.err")).string(), "\n");
        if (!o.partition.empty())
            t += strCat("#SBATCH --partition=", o.partition, "\n");
        for (const std::string& option : o.sbatchOptions)
            t += strCat("#SBATCH ", option, "\n");
        t += "set -euo pipefail\n";
        t += strCat("exec ", shellQuoted(o.hairvox.string()), " sheet ", quotedShot, " --frames ",
                    shellQuoted(shown.toString()), "\n");
        job.sheetText = std::move(t);
    }
    return job;
}

namespace {

void writeScript(const fs::path& path, const std::string& text) {
    writeFileAtomically(path, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << text;
        out.flush();
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write"));
        out.close();
        fs::permissions(tmp, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                 fs::perms::others_read | fs::perms::others_exec);
    });
}

/// The job id `sbatch --parsable` printed ("123" or "123;cluster").
std::string jobIdFrom(const detail::ProcessResult& r, const fs::path& script) {
    std::string id = r.output.substr(0, r.output.find_first_of(";\n"));
    if (r.exitCode != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
        throw InputError(strCat("sbatch ", script.string(), " failed (exit ", r.exitCode,
                                "): ", r.errors.empty() ? r.output : r.errors));
    return id;
}

} // namespace

void writeFarmJob(const FarmJob& job) {
    std::error_code ec;
    fs::create_directories(job.logDir, ec);
    if (ec)
        throw InputError(
            strCat(job.logDir.string(), ": cannot create the log directory: ", ec.message()));
    writeScript(job.script, job.text);
    if (!job.sheetScript.empty())
        writeScript(job.sheetScript, job.sheetText);
}

SubmittedJob submitFarmJob(const FarmJob& job) {
    if (!detail::findProgram("sbatch"))
        throw InputError("sbatch is not on the PATH: submit from a Slurm submit host (Debian: "
                         "slurm-client), or write the script only with --dry-run");
    SubmittedJob out;
    out.jobId =
        jobIdFrom(detail::runProcess({"sbatch", "--parsable", job.script.string()}), job.script);
    if (!job.sheetScript.empty())
        out.sheetJobId = jobIdFrom(
            detail::runProcess({"sbatch", "--parsable", "--dependency=afterok:" + out.jobId,
                                "--kill-on-invalid-dep=yes", job.sheetScript.string()}),
            job.sheetScript);
    return out;
}

} // namespace hairvox::shots
