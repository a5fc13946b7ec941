#!/usr/bin/env python3
"""The documentation runs as written.

Every command a reader may copy sits in a fenced block marked ```sh, one command per line (an
alternative goes in a comment, never as `a|b` inside the command). This test takes those lines
from README.md, docs/*.md and examples/**/README.md and runs them in order, one document at a
time, in a scratch folder holding a copy of docs/ and examples/ and with a scratch HOME, with the
built csfcal first on PATH. It fails naming the document, the line, the command and its output
when one fails.

Skipped, and said so: a line ending in `# needs: meter`, `# needs: display`, `# needs: server`
or `# needs: root` (a photometer, a window, a PostgreSQL server, or installing into the system),
and a line with a placeholder such as `<FILE>`. Also refused: a ```sh line continued with a
backslash, and a csfcal command in an indented block, where this test would not see it.

    test_docs_run.py SOURCE_ROOT build/cli/csfcal=PATH [build/examples/lod/lod=PATH ...] [DOC ...]

Each REL=PATH puts the built program PATH at REL in the scratch folder, as a source root built
with `meson setup build && ninja -C build` holds it; build/cli is also first on PATH, so the
commands call it `csfcal`, as an installed one is called. Without DOCs: README.md, docs/*.md and
examples/**/README.md.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

NEEDS = {"meter", "display", "server", "root"}
PLACEHOLDER = re.compile(r"<[A-Z][A-Z0-9_.-]*>")
NEEDS_MARK = re.compile(r"#\s*needs:\s*([a-z]+(?:\s*,\s*[a-z]+)*)")
TIMEOUT_S = 300


def commands(path):
    """(line number, command, skip reason or None) for each ```sh line, and the problems."""
    out, problems = [], []
    in_sh = in_fence = False
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    for no, line in enumerate(lines, 1):
        fence = re.match(r"^\s*```(\S*)", line)
        if fence:
            in_sh = not in_fence and fence.group(1) == "sh"
            in_fence = not in_fence
            continue
        if not in_fence:
            # an indented block that holds a command escapes this test
            if re.match(r"^( {4,}|\t)(\$ )?csfcal ", line):
                problems.append(f"{path}:{no}: a csfcal command outside a ```sh block: {line.strip()}")
            continue
        if not in_sh:
            continue
        cmd = line.strip()
        if not cmd or cmd.startswith("#"):
            continue
        if cmd.endswith("\\"):
            problems.append(f"{path}:{no}: a command continued onto the next line; write it as one line")
            continue
        if cmd.startswith("$ "):
            problems.append(f"{path}:{no}: a '$ ' prompt in a ```sh block; write the bare command")
            continue
        need = NEEDS_MARK.search(cmd)
        if need:
            kinds = {k.strip() for k in need.group(1).split(",")}
            unknown = kinds - NEEDS
            if unknown:
                problems.append(f"{path}:{no}: unknown '# needs:' {', '.join(sorted(unknown))} "
                                f"(known: {', '.join(sorted(NEEDS))})")
            out.append((no, cmd, "needs " + ", ".join(sorted(kinds))))
        elif PLACEHOLDER.search(cmd):
            out.append((no, cmd, "placeholder " + PLACEHOLDER.search(cmd).group(0)))
        else:
            out.append((no, cmd, None))
    if in_fence:
        problems.append(f"{path}: a fenced block is not closed")
    return out, problems


def scratch(root, bins):
    """A folder with copies of docs/ and examples/, the built programs, a HOME, and the
    environment to run in."""
    d = tempfile.mkdtemp(prefix="csfcal-docs-")
    for sub in ("docs", "examples"):
        shutil.copytree(os.path.join(root, sub), os.path.join(d, sub), symlinks=True)
    for rel, path in bins.items():
        os.makedirs(os.path.dirname(os.path.join(d, rel)), exist_ok=True)
        os.symlink(path, os.path.join(d, rel))
    home = os.path.join(d, "home")
    os.mkdir(home)
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("XDG_") and k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env.update(HOME=home, PATH=os.path.join(d, "build", "cli") + os.pathsep + env.get("PATH", "/usr/bin:/bin"),
               EGL_PLATFORM="surfaceless")
    return d, env


def run_doc(path, root, bins):
    cmds, problems = commands(path)
    rel = os.path.relpath(path, root)
    problems = [p.replace(path, rel) for p in problems]
    d, env = scratch(root, bins)
    ran = skipped = 0
    try:
        for no, cmd, skip in cmds:
            first = cmd.split()[0]
            if not skip and first.startswith("build/") and not os.path.exists(os.path.join(d, first)):
                skip = f"{first} is not built here"
            if skip:
                skipped += 1
                print(f"  skip {rel}:{no} ({skip}): {cmd}")
                continue
            ran += 1
            t0 = time.monotonic()
            try:
                p = subprocess.run(["bash", "-c", "set -o pipefail; " + cmd], cwd=d, env=env,
                                   stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, timeout=TIMEOUT_S)
                rc, output = p.returncode, p.stdout.decode("utf-8", "replace")
            except subprocess.TimeoutExpired as e:
                rc, output = "timeout", (e.stdout or b"").decode("utf-8", "replace")
            print(f"  ran  {rel}:{no} (exit {rc}, {time.monotonic() - t0:.1f} s): {cmd}")
            if rc != 0:
                tail = "\n".join(output.rstrip().split("\n")[-15:])
                problems.append(f"{rel}:{no}: exit {rc}: {cmd}\n{tail}")
    finally:
        shutil.rmtree(d, ignore_errors=True)
    print(f"{rel}: {ran} commands ran, {skipped} skipped")
    return problems


def main():
    root = os.path.abspath(sys.argv[1])
    bins = dict(a.split("=", 1) for a in sys.argv[2:] if "=" in a)
    bins = {rel: os.path.abspath(path) for rel, path in bins.items()}
    docs = [a for a in sys.argv[2:] if "=" not in a]
    docs = docs or (["README.md"] + sorted(glob.glob("docs/*.md", root_dir=root)) +
                    sorted(glob.glob("examples/**/README.md", root_dir=root, recursive=True)))
    problems = []
    for doc in docs:
        problems += run_doc(os.path.join(root, doc), root, bins)
    for p in problems:
        print("FAIL " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
