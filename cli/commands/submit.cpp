// hairvox submit SHOT.json [--frames F] [--per-task N] [--partition P] [--time T]
//                [--cpus N] [--mem M] [--max-running N] [--sbatch=OPTION ...]
//                [--cache DIR] [--sheet] [--force] [--dry-run]
// Renders a shot on a Slurm cluster: the frames not done (hairvox status) in
// array tasks of --per-task frames (shots/slurm.h), submitted with sbatch.
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/shots/frame_status.h>
#include <hairvox/shots/shot.h>
#include <hairvox/shots/slurm.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

namespace hairvox::cli {

namespace {

namespace fs = std::filesystem;

struct SubmitCommandOptions {
    std::string shot, frames, partition, time, memory, cacheDir, hairvox;
    std::size_t perTask = 8, maxRunning = 0;
    std::vector<std::string> sbatch;
    int cpus = 0;
    bool sheet = false, force = false, dryRun = false;
};

void runSubmit(const SubmitCommandOptions& opt) {
    const shots::Shot shot = shots::Shot::load(opt.shot);
    const shots::FrameSet asked =
        opt.frames.empty() ? shot.frames() : shot.select(shots::FrameSet::parse(opt.frames));
    // Only what is not done goes to the farm (each task checks again).
    shots::FrameSet frames = asked;
    if (!opt.force) {
        const auto statuses = shots::shotStatus(shot, asked);
        const shots::FrameSet blocked = shots::framesIn(statuses, shots::FrameState::Blocked);
        if (!blocked.empty()) {
            std::string why;
            for (const auto& s : statuses)
                if (s.state == shots::FrameState::Blocked) {
                    why = s.reason;
                    break;
                }
            throw InputError(strCat(opt.shot, ": frames ", blocked.toString(),
                                    " cannot be rendered (", why, "); nothing was submitted"));
        }
        std::vector<int> todo;
        for (const auto& s : statuses)
            if (s.state != shots::FrameState::Done)
                todo.push_back(s.frame);
        frames = shots::FrameSet::of(std::move(todo));
        if (frames.empty()) {
            std::cout << "hairvox: " << opt.shot << ": all " << asked.size() << " frames ("
                      << asked.toString() << ") are done; nothing to submit (--force renders "
                      << "them again)\n";
            return;
        }
    }
    const fs::path shotFile = fs::absolute(opt.shot).lexically_normal();
    shots::SubmitOptions options;
    options.shotFile = shotFile;
    options.workDir = fs::current_path();
    options.farmDir = shotFile.parent_path() / (shotFile.stem().string() + ".farm");
    options.cacheDir = opt.cacheDir.empty() ? options.farmDir / "cache"
                                            : fs::absolute(opt.cacheDir).lexically_normal();
    options.hairvox = opt.hairvox.empty() ? fs::read_symlink("/proc/self/exe")
                                          : fs::absolute(opt.hairvox).lexically_normal();
    options.perTask = opt.perTask;
    options.cpus = opt.cpus > 0
                       ? opt.cpus
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    options.partition = opt.partition;
    options.timeLimit = opt.time;
    options.memory = opt.memory;
    options.maxRunning = opt.maxRunning;
    options.sbatchOptions = opt.sbatch;
    options.force = opt.force;
    options.sheet = opt.sheet;
    const shots::FarmJob job = shots::makeFarmJob(options, frames, asked);
    shots::writeFarmJob(job);
    const std::string summary = strCat(
        "frames ", frames.toString(), " of ", opt.shot, " (", frames.size(), " of ", asked.size(),
        " asked for not done) as ", job.chunks.size(), " array task(s) of up to ", options.perTask,
        " frames, ", options.cpus, " CPU(s) each");
    if (opt.dryRun) {
        std::cout << "hairvox: dry run, nothing submitted: " << summary << "\n"
                  << "script " << job.script.string() << ":\n"
                  << job.text;
        if (!job.sheetScript.empty())
            std::cout << "script " << job.sheetScript.string() << " (after every task succeeded):\n"
                      << job.sheetText;
        return;
    }
    const shots::SubmittedJob submitted = shots::submitFarmJob(job);
    std::cout << "hairvox: submitted job " << submitted.jobId << ": " << summary << "\n"
              << "  script   " << job.script.string() << "\n"
              << "  logs     "
              << (job.logDir /
                  (shotFile.stem().string() + "-" + submitted.jobId + "_<task>.out|.err"))
                     .string()
              << "\n"
              << "  cache    " << options.cacheDir.string() << "\n";
    if (!submitted.sheetJobId.empty())
        std::cout << "  sheet    job " << submitted.sheetJobId
                  << " makes the movie and contact sheet once every task succeeded\n";
    std::cout << "  follow   squeue -j " << submitted.jobId << "   (tasks pending and running)\n"
              << "           sacct -j " << submitted.jobId
              << " -X   (each task's state and time; needs Slurm accounting)\n"
              << "           hairvox status " << opt.shot << "   (frames done, missing, stale)\n"
              << "  after a failure or cancel: hairvox submit " << opt.shot
              << " again renders only the frames not done\n";
}

} // namespace

void addSubmitCommand(CLI::App& app) {
    auto opt = std::make_shared<SubmitCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "submit", "Render a shot's frames on a Slurm cluster as an array job (docs/farm.md)");
    cmd->add_option("shot", opt->shot, "Shot file: a scene with \"frames\"")->required();
    cmd->add_option("--frames", opt->frames,
                    "Frames (1-240, 1-240x2, 7, lists; default: the shot's); only those not "
                    "done are submitted");
    cmd->add_option("--per-task", opt->perTask, "Frames per array task (default 8)")
        ->check(CLI::Range(std::size_t(1), std::size_t(100000)));
    cmd->add_option("--partition", opt->partition, "Slurm partition (default: the cluster's)");
    cmd->add_option("--time", opt->time, "Time limit per task, [days-]HH:MM:SS");
    cmd->add_option("--cpus", opt->cpus,
                    "CPUs per task, the render's threads (default: this machine's CPUs)")
        ->check(CLI::Range(1, 4096));
    cmd->add_option("--mem", opt->memory, "Memory per task, e.g. 8G (default: the partition's)");
    cmd->add_option("--max-running", opt->maxRunning,
                    "Tasks running at once at most (Slurm's --array=...%N; default: no limit)")
        ->check(CLI::Range(std::size_t(1), std::size_t(100000)));
    cmd->add_option("--sbatch", opt->sbatch,
                    "One more sbatch option for the job's script, e.g. --sbatch=--account=show "
                    "--sbatch=--qos=low (repeatable)")
        ->allow_extra_args(false);
    cmd->add_option("--cache", opt->cacheDir,
                    "Shared cache directory on a file system every node sees (default: "
                    "<shot>.farm/cache beside the shot)");
    cmd->add_option("--hairvox", opt->hairvox,
                    "The hairvox executable the tasks run (default: this one; the same path "
                    "on every node)");
    cmd->add_flag(
        "--sheet", opt->sheet,
        "Also submit a job that makes the movie and contact sheet when the frames are done");
    cmd->add_flag("--force", opt->force, "Render the frames that are done too");
    cmd->add_flag("--dry-run", opt->dryRun, "Write and print the sbatch script; submit nothing");
    cmd->callback([opt] { runSubmit(*opt); });
}

} // namespace hairvox::cli
