// hairvox shots: a shot as a Slurm array job (docs/farm.md). The frames to
// render go in chunks of `perTask` to the tasks of one array job; each task
// runs `hairvox render SHOT --frames <its chunk> --threads <its CPUs>
// --cache DIR` in the directory hairvox submit ran in (the shot's outputs are
// relative to it), so each skips the frames already done and takes the fiber
// grid and the lights' preparation from the shared cache. The sbatch script
// and the tasks' logs go to a directory beside the shot (<shot>.farm/);
// Slurm's own sbatch submits it. Optionally a second job, run once every
// task has succeeded, makes the movie and contact sheet (`hairvox sheet`).
#pragma once

#include <hairvox/shots/frame_set.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace hairvox::shots {

struct SubmitOptions {
    std::filesystem::path shotFile; ///< absolute
    std::filesystem::path workDir;  ///< where the tasks run (the shot's outputs are relative to it)
    std::filesystem::path farmDir;  ///< the script and logs; absolute
    std::filesystem::path cacheDir; ///< the shared cache; absolute
    std::filesystem::path hairvox;  ///< the executable the tasks run; absolute
    std::size_t perTask = 8;        ///< frames per array task, [1, 100000]
    int cpus = 1;                   ///< --cpus-per-task, and the render's threads, [1, 4096]
    std::string partition;          ///< empty: the cluster's default
    std::string timeLimit;          ///< per task, Slurm's [days-]HH:MM:SS; empty: the partition's
    std::string memory;             ///< per task, e.g. "8G"; empty: the partition's default
    std::size_t maxRunning = 0;     ///< tasks running at once (--array=...%N); 0: no limit
    /// More sbatch options, each an #SBATCH line: "--account=show",
    /// "--qos=low", "--exclude=node07" (each starts with '-', one line).
    std::vector<std::string> sbatchOptions;
    bool force = false;                  ///< tasks render frames that are done too
    bool sheet = false;                  ///< a dependent job that runs hairvox sheet
    std::vector<std::string> renderArgs; ///< more arguments of every task's render

    /// InputError naming the option and its valid form.
    void validate() const;
};

/// The job as written: the script of the array job (and of the sheet job).
struct FarmJob {
    std::filesystem::path script; ///< <farmDir>/<shot stem>.sbatch
    std::string text;
    std::filesystem::path sheetScript; ///< empty without SubmitOptions::sheet
    std::string sheetText;
    std::vector<FrameSet> chunks; ///< array task i renders chunks[i]
    std::filesystem::path logDir;
};

/// The job that renders `frames` (SubmitOptions validated; frames not
/// empty), and whose sheet job (SubmitOptions::sheet) shows `shown`: the
/// frames asked for, done before or not.
FarmJob makeFarmJob(const SubmitOptions& options, const FrameSet& frames, const FrameSet& shown);

/// Writes the scripts (atomically, executable) and creates the log directory.
void writeFarmJob(const FarmJob& job);

struct SubmittedJob {
    std::string jobId;      ///< the array job's
    std::string sheetJobId; ///< empty without a sheet job
};

/// Submits the written job with sbatch (found on the PATH). InputError with
/// sbatch's message when it refuses, or when there is no sbatch.
SubmittedJob submitFarmJob(const FarmJob& job);

} // namespace hairvox::shots
