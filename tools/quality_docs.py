#!/usr/bin/python3
"""Regenerates the results of docs/benchmarks.md's quality benchmark, tables and plots, in one command.

    /usr/bin/python3 tools/quality_docs.py                    # from the project root, after a build
    /usr/bin/python3 tools/quality_docs.py --data DIR --no-plots -- --set tum

Runs `posefair bench quality` and `posefair bench streams`, puts what each prints (every table
of the Results section and its list of where the defaults lose; the generated streams' table)
between the document's marker lines for it, each stamped with the date, the commit and how long
the run took, and draws the plots (tools/plot_quality.py) into the image folder. Text outside
the markers is the project's own and is left as it is. Nothing is written when a benchmark fails
or a pair of markers is missing (exit 65, the file named). Arguments after `--` go to
`bench quality` (`--set`); `--quick` runs both benchmarks short.
"""
import argparse
import datetime
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EX_DATAERR = 65


class MarkerError(Exception):
    pass


def markers(name):
    """The begin line's start and the end line of the block `name` ("quality", "streams")."""
    return "<!-- posefair bench %s: begin" % name, "<!-- posefair bench %s: end -->" % name


def splice(doc, name, block):
    """doc with the text between the marker lines of block `name` replaced by block (markers kept)."""
    begin, end = markers(name)
    lines = doc.splitlines(keepends=True)
    begins = [i for i, l in enumerate(lines) if l.startswith(begin)]
    ends = [i for i, l in enumerate(lines) if l.rstrip("\n") == end]
    if len(begins) != 1 or len(ends) != 1:
        raise MarkerError(
            "needs exactly one line starting '%s' and one line '%s' (found %d and %d)" % (begin, end, len(begins), len(ends)))
    b, e = begins[0], ends[0]
    if e < b:
        raise MarkerError("the line '%s' (line %d) comes before '%s' (line %d)" % (end, e + 1, begin, b + 1))
    body = block if block.endswith("\n") else block + "\n"
    begin_line = begin + " (tools/quality_docs.py writes what is between these lines; edit outside them) -->\n"
    return "".join(lines[:b]) + begin_line + body + "".join(lines[e:])


def results_block(printed):
    """The benchmark's stdout as it goes into the document: each heading one level down (its
    "## Smoothing" goes under the document's "## Results"), its note of the files it wrote left out."""
    kept = ["#" + l if l.startswith("#") else l for l in printed.splitlines() if not l.startswith("wrote ")]
    while kept and not kept[-1].strip():
        kept.pop()
    return "\n".join(kept) + "\n"


def commit(root, written):
    """HEAD, and whether anything but the files this run writes differs from it."""
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                             check=True).stdout.strip()
        excluded = [":(exclude)" + str(Path(w).resolve()) for w in written]
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no", "--", str(root)] + excluded,
                               capture_output=True, text=True, check=True).stdout.strip()
        return rev + (" with uncommitted changes" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown commit"


def build_type(posefair):
    """CMAKE_BUILD_TYPE from the CMakeCache.txt of the build the binary is in, if it can be found."""
    for parent in Path(posefair).resolve().parents:
        cache = parent / "CMakeCache.txt"
        if cache.is_file():
            for line in cache.read_text(errors="replace").splitlines():
                if line.startswith("CMAKE_BUILD_TYPE:"):
                    return line.split("=", 1)[1] or "no build type"
            return "no build type"
    return "unknown build"


def write_atomically(path, text):
    fd, tmp = tempfile.mkstemp(dir=str(path.parent), prefix=path.name + ".")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def main(argv):
    root = Path(__file__).resolve().parent.parent
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--posefair", default="build/tools/posefair", help="the posefair binary (default: %(default)s)")
    p.add_argument("--data", help="folder with the recorded data sets (default: the benchmark's, $POSEFAIR_DATA or ../shared/data)")
    p.add_argument("--doc", default=str(root / "docs" / "benchmarks.md"), help="the document to update (default: docs/benchmarks.md)")
    p.add_argument("--img", default=str(root / "docs" / "img"), help="folder for the plots (default: docs/img)")
    p.add_argument("-o", "--output", default="build/bench-quality", help="folder for the benchmark's CSV files (default: %(default)s)")
    p.add_argument("--no-plots", action="store_true", help="update the tables only (the plots need python3-matplotlib)")
    p.add_argument("--quick", action="store_true", help="both benchmarks short (seconds; synthetic data only)")
    args, bench_args = p.parse_known_args(argv)
    bench_args = [a for a in bench_args if a != "--"]
    doc = Path(args.doc)

    # Both benchmarks, each into the block of its name.
    runs = [("quality", [args.posefair, "bench", "quality", "-o", args.output] + (["--data", args.data] if args.data else []) +
             (["--quick"] if args.quick else []) + bench_args),
            ("streams", [args.posefair, "bench", "streams", "-o", args.output + "/streams"] + (["--quick"] if args.quick else []))]

    # The markers are checked first: a run of minutes should not end in a document it cannot update.
    try:
        text = doc.read_text()
        for name, _ in runs:
            splice(text, name, "")
    except OSError as e:
        print("quality_docs: %s: %s" % (doc, e.strerror), file=sys.stderr)
        return EX_DATAERR
    except MarkerError as e:
        print("quality_docs: %s: %s" % (doc, e), file=sys.stderr)
        return EX_DATAERR

    for name, cmd in runs:
        print("quality_docs: running", " ".join(cmd), file=sys.stderr)
        started = time.monotonic()
        run = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)  # its progress (stderr) goes to ours
        if run.returncode != 0:
            print("quality_docs: the benchmark exited %d; %s is unchanged" % (run.returncode, doc), file=sys.stderr)
            return run.returncode
        took = time.monotonic() - started
        stamp = "What `%s` printed on %s UTC (%s, %s build; %d:%02d in all, on a machine with %d cores), written by `tools/quality_docs.py`.\n\n" % (
            " ".join(["posefair"] + cmd[1:]), datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
            commit(root, [args.doc, args.img]), build_type(args.posefair), int(took) // 60, int(took) % 60, os.cpu_count() or 0)
        text = splice(text, name, stamp + results_block(run.stdout))
    write_atomically(doc, text)
    print("quality_docs: updated", doc, file=sys.stderr)

    if not args.no_plots:
        plots = subprocess.run(["/usr/bin/python3", str(root / "tools" / "plot_quality.py"), args.output, args.img])
        if plots.returncode != 0:
            print("quality_docs: the plots failed (python3-matplotlib: tools/setup-debian.sh --plots)", file=sys.stderr)
            return plots.returncode
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
