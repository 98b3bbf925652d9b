"""README's commands run against this build, so that none stops working unnoticed.

Every ```sh block of README.md is split into commands (a line, or lines joined
by a trailing backslash) and each is run with bash, in order, in a fresh
directory laid out as the checkout's root: `data` and `docs` are links to the
checkout's, `hairvox` on PATH is this build's executable (HAIRVOX_BINARY), and
`build/release/cli/hairvox` leads to it too. Each must exit with 0 within its
time limit.

Not run (SKIPPED, each with its reason): the two setup commands (they install
packages and build), the benchmark (minutes), the full 240-frame shot and its sheet (the
preview of every 48th frame and its sheet run the same code) and the Slurm
submission (no cluster here; tests/shots/slurm_test.cpp runs a real one). Made cheaper
(CHEAPER): the path-traced reference runs at 4 samples instead of 256, so the
`compare` after it has its input. A skip or substitution that no longer
matches a README command fails the test, so the lists cannot go stale.

Also checked: every relative link and image of README names a file of the
checkout.
"""

import os
import pathlib
import re
import shlex
import subprocess
import tempfile
import time

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("HAIRVOX_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
README = SOURCE_DIR / "README.md"

# Commands not run: a regular expression matching the whole command, and why.
SKIPPED = [
    (r"bash scripts/demo\.sh\b.*", "setup: installs packages and builds"),
    (r"bash scripts/test\.sh\b.*", "setup: installs packages, builds and runs every test"),
    (r"hairvox bench\b.*", "the benchmark takes minutes"),
    (r"hairvox render data/shots/turntable\.json --frames 1-240\s*(#.*)?",
     "240 frames at 1024²; the preview of every 48th frame runs the same code"),
    (r"hairvox sheet data/shots/turntable\.json\s*(#.*)?",
     "needs all 240 frames; the preview's sheet runs the same code"),
    (r"hairvox submit\b.*", "needs a Slurm cluster (tests/shots/slurm_test.cpp runs one)"),
]

# Commands run cheaper: (regular expression, replacement), applied to the command.
CHEAPER = [
    (r"(hairvox render --integrator path )--spp 256", r"\1--spp 4"),
]

TIME_LIMIT_S = 300


def sh_commands(text):
    """The commands of the ```sh blocks: one per line, backslash continuations joined."""
    commands = []
    for block in re.findall(r"^```sh\n(.*?)^```", text, flags=re.S | re.M):
        pending = ""
        for line in block.splitlines():
            if line.rstrip().endswith("\\"):
                pending += line.rstrip()[:-1] + " "
                continue
            command = (pending + line).strip()
            pending = ""
            if command and not command.startswith("#"):
                commands.append(command)
        assert not pending, f"README: a ```sh block ends in a continuation: {pending!r}"
    return commands


def without_comment(command):
    """The command without a trailing `# comment` (README's commands quote no '#')."""
    return command.split(" #", 1)[0].strip()


def hairvox_binary():
    binary = os.environ.get("HAIRVOX_BINARY")
    if not binary:
        pytest.fail("HAIRVOX_BINARY is not set: run this test through ctest (tests/CMakeLists.txt)")
    binary = pathlib.Path(binary)
    if not binary.is_file():
        pytest.fail(f"HAIRVOX_BINARY {binary} does not exist: build the hairvox target first")
    return binary


def test_readme_links_name_files_of_the_checkout():
    text = README.read_text(encoding="utf-8")
    targets = re.findall(r"\]\(([^)\s]+)\)", text)
    assert targets, "README has no links"
    missing = []
    for target in targets:
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue
        path = target.split("#", 1)[0]
        if not (SOURCE_DIR / path).exists():
            missing.append(target)
    assert not missing, f"README links to files that do not exist: {missing}"


def test_readme_commands_run():
    binary = hairvox_binary()
    commands = sh_commands(README.read_text(encoding="utf-8"))
    assert len(commands) >= 10, f"README: expected its ```sh blocks, found {commands}"

    used_skips, used_cheaper = set(), set()
    with tempfile.TemporaryDirectory(prefix="hairvox-readme-") as tmp:
        root = pathlib.Path(tmp)
        for name in ("data", "docs"):
            (root / name).symlink_to(SOURCE_DIR / name)
        cli_dir = root / "build" / "release" / "cli"
        cli_dir.mkdir(parents=True)
        (cli_dir / "hairvox").symlink_to(binary)
        env = dict(os.environ)
        env["PATH"] = f"{cli_dir}{os.pathsep}{env.get('PATH', '')}"
        env.setdefault("HAIRVOX_CACHE_DIR", str(root / "cache"))

        failures, ran = [], []
        for command in commands:
            bare = without_comment(command)
            skip = next((i for i, (pattern, _) in enumerate(SKIPPED)
                         if re.fullmatch(pattern, command) or re.fullmatch(pattern, bare)), None)
            if skip is not None:
                used_skips.add(skip)
                continue
            for i, (pattern, replacement) in enumerate(CHEAPER):
                if re.search(pattern, bare):
                    bare = re.sub(pattern, replacement, bare)
                    used_cheaper.add(i)
            start = time.monotonic()
            try:
                result = subprocess.run(["bash", "-euo", "pipefail", "-c", bare], cwd=root, env=env,
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        timeout=TIME_LIMIT_S)
                code, output = result.returncode, result.stdout.decode(errors="replace")
            except subprocess.TimeoutExpired as e:
                code, output = "timeout", (e.stdout or b"").decode(errors="replace")
            seconds = time.monotonic() - start
            ran.append(f"{seconds:6.1f} s  {bare}")
            if code != 0:
                failures.append(f"$ {bare}\n(exit {code})\n{output[-3000:]}")
        print("README commands run:\n" + "\n".join(ran))

    stale = [SKIPPED[i][0] for i in range(len(SKIPPED)) if i not in used_skips]
    stale += [CHEAPER[i][0] for i in range(len(CHEAPER)) if i not in used_cheaper]
    assert not stale, f"skip or substitution patterns match no README command any more: {stale}"
    assert not failures, "README commands failed:\n\n" + "\n\n".join(failures)
