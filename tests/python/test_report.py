"""Tests of the report builder (scripts/report) and of scripts/reproduce, on hand-built run
directories (fakes.py) and a fake caplab; run with `/usr/bin/python3 -m pytest -q tests/python`."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(REPO / "reports"))

import fakes  # noqa: E402
from caplab_report import references as refmod  # noqa: E402
from caplab_report.runs import load_run  # noqa: E402
from pages import CHROMIUM, PYTHON, assert_self_contained, chromium, parse, summary, write_case  # noqa: E402
PASS_TITLE = "Flow past a circular cylinder, Re = 100 (passing fixture)"
FAIL_TITLE = "Flow past a circular cylinder, Re = 200 (failing fixture)"
DIVERGED_TITLE = "Cylinder that diverges (fixture)"
INPUT_ERROR_TITLE = "Case rejected by the loader (fixture)"
MISSING_TITLE = "Case never run (fixture)"


# ---- fixture: a results tree with every outcome ------------------------------------------------

@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("report")
    results, catalogue, out = root / "results", root / "catalogue", root / "out"
    quick = results / "quick"
    cases = {
        "pass": fakes.cylinder_case("ch2/cylinder_re100", PASS_TITLE, 100),
        "fail": fakes.cylinder_case("ch2/cylinder_re200", FAIL_TITLE, 200),
        "diverged": fakes.cylinder_case("ch2/cylinder_diverging", DIVERGED_TITLE, 100),
    }
    for outcome, case in cases.items():
        write_case(catalogue, case)
        fakes.make_run_dir(quick / case["id"].replace("/", "__"), case, "quick", outcome)
    # caplab refused the input: no run directory, only the record of scripts/reproduce and the log.
    bad = fakes.cylinder_case("ch2/cylinder_bad_input", INPUT_ERROR_TITLE)
    write_case(catalogue, bad)
    fakes.write_json(quick / "ch2__cylinder_bad_input.reproduce.json",
                     {"case_id": bad["id"], "fidelity": "quick", "exit_code": 2})
    (quick / "ch2__cylinder_bad_input.log").write_text("error: /numerics/end_time: expected a number > 0\n")
    # in the catalogue, never run
    write_case(catalogue, fakes.cylinder_case("ch2/cylinder_never_run", MISSING_TITLE))
    fakes.write_json(catalogue / "schema.json", {"title": "not a case"})

    proc = subprocess.run([PYTHON, str(REPO / "scripts" / "report"), "--results", str(results), "--out", str(out),
                           "--catalogue", str(catalogue), "--references", str(REPO / "references")]
                          + ([] if CHROMIUM else ["--no-pdf"]), capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return {"root": root, "out": out, "proc": proc}


# ---- report -----------------------------------------------------------------------------------

def test_pages_written(built):
    out = built["out"]
    for rel in ("index.html", "references.html", "chapter2/index.html"):
        assert (out / rel).is_file(), rel


@pytest.mark.parametrize("page", ["index.html", "chapter2/index.html"])
def test_verdicts_listed(built, page):
    rows = summary(parse(built["out"] / page))
    expected = {  # case: (run status, sanity, accuracy, verdict)
        "ch2/cylinder_re100": ("ok", "PASS", "PASS", "PASS"),
        "ch2/cylinder_re200": ("ok", "PASS", "FAIL", "FAIL"),
        "ch2/cylinder_diverging": ("DIVERGED", "FAIL", "N/A", "FAIL"),
        "ch2/cylinder_bad_input": ("INPUT ERROR", "FAIL", "N/A", "FAIL"),
        "ch2/cylinder_never_run": ("MISSING", "MISSING", "MISSING", "MISSING"),
    }
    assert set(rows) == set(expected), rows.keys()
    for case, (status, sanity, accuracy, verdict) in expected.items():
        row = rows[case]
        assert row["run status"] == status, (case, row)
        assert row["sanity"] == sanity, (case, row)
        assert row["accuracy"].split()[0] == accuracy, (case, row)
        assert row["verdict"] == verdict, (case, row)


def test_self_contained(built):
    assert_self_contained(built["out"])


def test_chapter_content(built):
    html = (built["out"] / "chapter2" / "index.html").read_text(encoding="utf-8")
    page = parse(built["out"] / "chapter2" / "index.html")
    # one time-history figure per run with a series, plus the run time against error plot
    assert len(page.imgs) == 4
    for title in (PASS_TITLE, FAIL_TITLE, DIVERGED_TITLE, INPUT_ERROR_TITLE, MISSING_TITLE):
        assert title in html
    # the scorecard reference links to its provenance on the same page
    anchor = refmod.anchor_for("cylinder", "table_2_1.csv")
    assert f'href="#{anchor}"' in html and f'id="{anchor}"' in html
    assert "read from a table in the thesis text" in html
    # table 2.1 reproduced: literature rows and the caplab row, kinds kept apart
    for study in ("Lai and Peskin (2000)", "Russel and Wang (2003)", "Xu and Wang (2006)", "Chew and Shu (2002)"):
        assert study in html
    assert "caplab (quick)" in html and "validation (external data)" in html and "thesis value (reproduction)" in html
    # performance is its own verdict: the passing run is over its budget and still passes
    assert "over the budget of 40 s on 2 thread(s)" in html and "budget 40.0 s" in html
    assert "not judged (the case states no wall-time budget at level quick)" in html
    # the failed run shows caplab's message, the environment its build
    assert "expected a number &gt; 0" in html
    assert "0123456789ab" in html and "GNU 12.2.0" in html and "Test CPU" in html


def test_references_page(built):
    html = (built["out"] / "references.html").read_text(encoding="utf-8")
    for name in ("table_2_1.csv", "table_2_2.csv", "cylinder_extra_reference_values.csv"):
        assert f'id="{refmod.anchor_for("cylinder", name)}"' in html
    assert "0.5 rho U^2 D" in html and "10.1103/PhysRevE.56.434" in html


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed")
def test_screenshot(built):
    png = built["root"] / "chapter2.png"
    proc = chromium(f"--screenshot={png}", "--window-size=1280,2000",
                    (built["out"] / "chapter2" / "index.html").as_uri())
    assert png.is_file() and png.stat().st_size > 20_000, proc.stderr
    import matplotlib.image as mpimg
    import numpy as np
    img = mpimg.imread(png)
    assert img.shape[0] >= 1000 and img.shape[1] >= 1000
    colours = np.unique((img[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 50  # text, tables and badges, not a blank page
    assert img[..., :3].std() > 0.05


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed")
@pytest.mark.parametrize("rel, needles", [
    ("chapter2/index.pdf", [PASS_TITLE, FAIL_TITLE, DIVERGED_TITLE, "FAIL", "PASS", "DIVERGED", "MISSING",
                            "Lai and Peskin"]),
    ("index.pdf", [PASS_TITLE, "FAIL", "MISSING"]),
])
def test_pdf(built, rel, needles):
    pdf = built["out"] / rel
    assert pdf.is_file(), built["proc"].stderr
    info = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True).stdout
    pages = int(re.search(r"^Pages:\s+(\d+)", info, re.M).group(1))
    assert pages >= (3 if rel.startswith("chapter") else 1)
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
    flat = " ".join(text.split())
    for needle in needles:
        assert needle in flat, needle


# ---- parts that must be able to fail ----------------------------------------------------------

def test_killed_run_is_incomplete(tmp_path):
    case = fakes.cylinder_case()
    run_dir = fakes.make_run_dir(tmp_path / "quick" / "ch2__cylinder_re100", case, "quick", "running")
    run = load_run(run_dir, case["id"], "quick")
    assert run.status == "incomplete" and run.verdict == "fail" and run.sanity == "fail"


def test_killed_run_is_told_from_a_live_one_by_the_directory_lock(tmp_path):
    """A live caplab holds an exclusive flock on its run directory (solver/io/run_directory.cpp):
    the report says "writing it now" while one is held and "killed" once it is gone."""
    import fcntl
    import os
    case = fakes.cylinder_case()
    run_dir = fakes.make_run_dir(tmp_path / "quick" / "ch2__cylinder_re100", case, "quick", "running")
    fd = os.open(run_dir, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # as the running caplab does
        live = load_run(run_dir, case["id"], "quick")
    finally:
        os.close(fd)
    killed = load_run(run_dir, case["id"], "quick")
    assert live.status == killed.status == "incomplete"
    assert any("writing it now" in p for p in live.problems), live.problems
    assert any("was killed" in p for p in killed.problems), killed.problems
    assert not any("writing it now" in p for p in killed.problems)


def test_stopped_run_is_incomplete(tmp_path):
    """Ctrl-C or SIGTERM: caplab finished the manifest "failed" with an "interrupted" entry."""
    case = fakes.cylinder_case()
    run_dir = fakes.make_run_dir(tmp_path / "quick" / "ch2__cylinder_re100", case, "quick", "running")
    manifest = json.loads((run_dir / "manifest.json").read_text())
    manifest.update(status="failed", interrupted={"signal": "SIGINT", "step": 1200})
    fakes.write_json(run_dir / "manifest.json", manifest)
    run = load_run(run_dir, case["id"], "quick")
    assert run.status == "incomplete" and run.verdict == "fail"
    assert any("stopped by SIGINT after step 1200" in p for p in run.problems)


def test_unscored_run_is_not_a_pass(tmp_path):
    case = fakes.cylinder_case()
    run_dir = fakes.make_run_dir(tmp_path / "r", case, "quick", "pass")
    (run_dir / "score.json").unlink()
    run = load_run(run_dir, case["id"], "quick")
    assert run.verdict == "not scored" and any("score.json" in p for p in run.problems)


def test_reference_mismatch_is_flagged():
    lib = refmod.ReferenceLibrary(REPO / "references")
    good = lib.resolve("references/cylinder/table_2_1.csv#Present:cd_re100", 1.438)
    assert not good.mismatch and good.kind == "thesis" and good.table_value == "1.438"
    assert lib.resolve("references/cylinder/table_2_1.csv#Lai and Peskin (2000):cd_re100", 1.4473).kind == "validation"
    bad = lib.resolve("references/cylinder/table_2_1.csv#Present:cd_re100", 1.5)
    assert bad.mismatch and "differs" in bad.note
    assert lib.resolve("references/cylinder/table_2_1.csv#Nobody:cd_re100", 1.0).mismatch
    assert lib.resolve("references/nowhere/x.csv#a:b", 1.0).kind == "unknown"


def test_reference_tables_match_thesis():
    """The CSVs hold the printed values of thesis tables 2.1 and 2.2 (thesis text, lines ~520-535)."""
    lib = refmod.ReferenceLibrary(REPO / "references")
    assert not lib.problems, lib.problems
    t21 = lib.get("cylinder", "table_2_1.csv")
    assert [r[0] for r in t21.rows] == ["Lai and Peskin (2000)", "Russel and Wang (2003)", "Xu and Wang (2006)",
                                         "Chew and Shu (2002)", "Present"]
    assert t21.row("Present") == ["Present", "1.438", "0.344", "0.166", "1.449", "0.709", "0.197"]
    assert t21.row("Lai and Peskin (2000)") == ["Lai and Peskin (2000)", "1.4473", "0.3299", "0.165", "", "", "0.190"]
    t22 = lib.get("cylinder", "table_2_2.csv")
    assert t22.column_values("cd_re100") == [1.454, 1.443, 1.438, 1.436, 1.435]
    assert t22.column_values("cd_re200") == [1.459, 1.451, 1.449, 1.448, 1.448]
    thesis = Path(__file__).resolve().parents[3] / "shared" / "thesis.txt"  # shared/ beside the checkout
    if thesis.is_file():
        text = thesis.read_text(encoding="utf-8")
        assert "Present\t1.438\t0.344\t0.166\t1.449\t0.709\t0.197" in text


# ---- scripts/reproduce ------------------------------------------------------------------------

FAKE_CAPLAB = """#!{python}
# Fake `caplab run CASE --fidelity F --out DIR`: writes a run directory like caplab would, and
# leaves one file per call in $FAKE_CAPLAB_CALLS. The outcome follows the case id.
import json, os, sys, time, uuid
sys.path.insert(0, {here!r})
import fakes
args = sys.argv[1:]
assert args[0] == "run", args
if args[1] == "--resume":  # continues the run directory: its case and level as it recorded them
    out = args[2]
    case = json.load(open(os.path.join(out, "case.json")))
    fidelity, call = json.load(open(os.path.join(out, "manifest.json")))["fidelity"], "resume"
else:
    case_file, fidelity, out = args[1], args[args.index("--fidelity") + 1], args[args.index("--out") + 1]
    case = json.load(open(case_file))
    call = fidelity
calls = os.environ["FAKE_CAPLAB_CALLS"]
open(os.path.join(calls, case["id"].replace("/", "__") + "." + call + "." + uuid.uuid4().hex), "w").close()
time.sleep(float(os.environ.get("FAKE_CAPLAB_SLEEP", "0")))
if "bad_input" in case["id"]:
    print("error: " + case_file + ": /physics/reynolds: expected a number > 0", file=sys.stderr)
    sys.exit(2)
outcome = "diverged" if "diverg" in case["id"] else ("fail" if "failing" in case["id"] else "pass")
fakes.make_run_dir(out, case, fidelity, outcome)
print("ran", case["id"])
sys.exit(fakes.EXIT_CODES[outcome])
"""


@pytest.fixture
def reproduce_env(tmp_path):
    catalogue = tmp_path / "catalogue"
    for cid in ("ch2/cylinder_re100", "ch2/cylinder_failing", "ch2/cylinder_diverging", "ch2/cylinder_bad_input"):
        write_case(catalogue, fakes.cylinder_case(cid, f"fixture {cid}"))
    fakes.write_json(catalogue / "schema.json", {"title": "not a case"})
    caplab = tmp_path / "caplab"
    caplab.write_text(FAKE_CAPLAB.format(python=PYTHON, here=str(HERE)))
    caplab.chmod(0o755)
    calls = tmp_path / "calls"
    calls.mkdir()
    env = dict(os.environ, FAKE_CAPLAB_CALLS=str(calls))
    results = tmp_path / "results"

    def reproduce(*extra, fidelity="quick", paths=None, report=False, env_extra=None, background=False,
                  new_session=False):
        cmd = [PYTHON, str(REPO / "scripts" / "reproduce"), "--caplab", str(caplab), "--fidelity", fidelity,
               "--results", str(results), *extra, *(paths or [str(catalogue)])]
        cmd += ["--report-out", str(tmp_path / "out"), "--catalogue", str(catalogue), "--no-pdf"] if report \
            else ["--no-report"]
        e = dict(env, **(env_extra or {}))
        if background:
            return subprocess.Popen(cmd, env=e, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                    start_new_session=new_session)
        return subprocess.run(cmd, env=e, capture_output=True, text=True, timeout=300)

    def count(case_id=None):
        files = [p.name for p in calls.iterdir()]
        return len([f for f in files if case_id is None or f.startswith(case_id.replace("/", "__") + ".")])

    return {"reproduce": reproduce, "count": count, "catalogue": catalogue, "caplab": caplab,
            "results": results, "out": tmp_path / "out"}


def test_reproduce_runs_then_skips(reproduce_env):
    r, count, results = reproduce_env["reproduce"], reproduce_env["count"], reproduce_env["results"]
    first = r(report=True)
    assert first.returncode == 1, first.stdout + first.stderr  # failing and diverged cases
    assert count() == 4
    assert (results / "quick" / "ch2__cylinder_re100" / "manifest.json").is_file()
    stamp = json.loads((results / "quick" / "ch2__cylinder_re100.reproduce.json").read_text())
    assert stamp["exit_code"] == 0 and stamp["fidelity"] == "quick" and len(stamp["case_sha256"]) == 64
    bad = json.loads((results / "quick" / "ch2__cylinder_bad_input.reproduce.json").read_text())
    assert bad["exit_code"] == 2 and bad["status"] is None
    assert "expected a number > 0" in (results / "quick" / "ch2__cylinder_bad_input.log").read_text()
    # the report was built and shows every case, the failures included
    rows = summary(parse(reproduce_env["out"] / "chapter2" / "index.html"))
    assert rows["ch2/cylinder_re100"]["verdict"] == "PASS"
    assert rows["ch2/cylinder_failing"]["verdict"] == "FAIL"
    assert rows["ch2/cylinder_diverging"]["run status"] == "DIVERGED"
    assert rows["ch2/cylinder_bad_input"]["run status"] == "INPUT ERROR"

    # second time: the finished runs (passed or scored outside tolerance) are skipped; the
    # diverged run and the rejected input run again
    second = r()
    assert "skipped" in second.stdout
    assert count("ch2/cylinder_re100") == 1 and count("ch2/cylinder_failing") == 1
    assert count("ch2/cylinder_diverging") == 2 and count("ch2/cylinder_bad_input") == 2

    # a changed case file runs again, the others do not
    case_file = reproduce_env["catalogue"] / "ch2" / "cylinder_re100.json"
    case = json.loads(case_file.read_text())
    case["numerics"]["end_time"] = 160
    fakes.write_json(case_file, case)
    r()
    assert count("ch2/cylinder_re100") == 2 and count("ch2/cylinder_failing") == 1

    # another fidelity is another run
    r(fidelity="standard", paths=[str(case_file)])
    assert count("ch2/cylinder_re100") == 3
    assert (results / "standard" / "ch2__cylinder_re100" / "manifest.json").is_file()

    # a changed binary reruns everything
    with open(reproduce_env["caplab"], "a") as fh:
        fh.write("# rebuilt\n")
    r()
    assert count("ch2/cylinder_re100") == 4 and count("ch2/cylinder_failing") == 2


def test_reproduce_reruns_killed_run(reproduce_env):
    r, count, results = reproduce_env["reproduce"], reproduce_env["count"], reproduce_env["results"]
    case_file = str(reproduce_env["catalogue"] / "ch2" / "cylinder_re100.json")
    assert r(paths=[case_file]).returncode == 0
    manifest = results / "quick" / "ch2__cylinder_re100" / "manifest.json"
    data = json.loads(manifest.read_text())
    data["status"] = "running"  # as left by a killed process
    fakes.write_json(manifest, data)
    r(paths=[case_file])
    assert count("ch2/cylinder_re100") == 2


def test_reproduce_resumes_stopped_run(reproduce_env):
    """A run stopped by a signal (or killed) after a checkpoint continues from it; not with --force,
    nor when the binary changed."""
    r, count, results = reproduce_env["reproduce"], reproduce_env["count"], reproduce_env["results"]
    case_file = str(reproduce_env["catalogue"] / "ch2" / "cylinder_re100.json")
    assert r(paths=[case_file]).returncode == 0
    run_dir = results / "quick" / "ch2__cylinder_re100"
    manifest = run_dir / "manifest.json"
    data = json.loads(manifest.read_text())

    def stop(status, **extra):
        fakes.write_json(manifest, dict(data, status=status, **extra))
        (run_dir / "series.h5").unlink(missing_ok=True)
        (run_dir / "checkpoint.h5").write_bytes(b"state")

    stop("failed", interrupted={"signal": "SIGINT", "step": 1200}, error="stopped by SIGINT")
    out = r(paths=[case_file])
    assert out.returncode == 0, out.stdout + out.stderr
    assert "resumed" in out.stdout and count("ch2/cylinder_re100.resume") == 1
    stamp = json.loads((results / "quick" / "ch2__cylinder_re100.reproduce.json").read_text())
    assert stamp["command"][1:3] == ["run", "--resume"] and stamp["resumed"] and stamp["status"] == "ok"
    assert r(paths=[case_file]).stdout.count("skipped") == 1  # finished now: up to date

    stop("running")  # killed after a checkpoint
    r(paths=[case_file])
    assert count("ch2/cylinder_re100.resume") == 2
    stop("failed", error="disk full")  # any other failure runs afresh
    r(paths=[case_file])
    assert count("ch2/cylinder_re100.resume") == 2 and count("ch2/cylinder_re100.quick") == 2
    stop("running")
    r("--force", paths=[case_file])
    assert count("ch2/cylinder_re100.resume") == 2 and count("ch2/cylinder_re100.quick") == 3
    stop("running")
    with open(reproduce_env["caplab"], "a") as fh:
        fh.write("# rebuilt\n")
    r(paths=[case_file])
    assert count("ch2/cylinder_re100.resume") == 2 and count("ch2/cylinder_re100.quick") == 4


def signal_during_first_case(reproduce_env, send, sleep):
    """Runs reproduce in a session of its own, calls send(pid) once the first (fake) case runs for
    `sleep` seconds, and returns (process, stdout, stderr) when it has ended."""
    proc = reproduce_env["reproduce"](env_extra={"FAKE_CAPLAB_SLEEP": str(sleep)}, background=True, new_session=True)
    deadline = time.monotonic() + 60
    while reproduce_env["count"]() == 0 and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(0.5)
    send(proc.pid)
    out, err = proc.communicate(timeout=120)
    return proc, out, err


def test_reproduce_ctrl_c_starts_no_further_case(reproduce_env):
    """Ctrl-C reaches reproduce and the running caplab (one process group): the running case stops
    (caplab checkpoints it), the queued ones do not start, and reproduce exits 130."""
    proc, out, err = signal_during_first_case(reproduce_env, lambda pid: os.killpg(pid, signal.SIGINT), 3)
    assert proc.returncode == 130, out + err
    assert reproduce_env["count"]() == 1, out + err
    assert "interrupted" in err


def test_reproduce_sigterm_starts_no_further_case_and_records_the_running_one(reproduce_env):
    """SIGTERM to reproduce alone (`kill PID`): the queued cases do not start, the running one
    finishes and is recorded, and reproduce exits 143. Before, reproduce died at once and the
    finished case kept a stamp without an exit code."""
    count, results = reproduce_env["count"], reproduce_env["results"]
    proc, out, err = signal_during_first_case(reproduce_env, lambda pid: os.kill(pid, signal.SIGTERM), 2)
    assert proc.returncode == 143, out + err
    assert count() == 1 and "stopped by SIGTERM" in err
    stamps = [json.loads(p.read_text()) for p in (results / "quick").glob("*.reproduce.json")]
    assert len(stamps) == 1 and stamps[0]["exit_code"] is not None, stamps


def test_reproduce_skips_a_run_finished_after_its_reproduce_stopped(reproduce_env):
    """A stamp without an exit code (its reproduce was killed while caplab went on) and a manifest
    that says ok: the run finished; it is not run again."""
    r, count, results = reproduce_env["reproduce"], reproduce_env["count"], reproduce_env["results"]
    case_file = str(reproduce_env["catalogue"] / "ch2" / "cylinder_re100.json")
    assert r(paths=[case_file]).returncode == 0
    stamp_file = results / "quick" / "ch2__cylinder_re100.reproduce.json"
    fakes.write_json(stamp_file, dict(json.loads(stamp_file.read_text()), exit_code=None))
    assert "skipped" in r(paths=[case_file]).stdout
    assert count("ch2/cylinder_re100") == 1


def test_reproduce_parallel_invocations_share_nothing(reproduce_env):
    """Two invocations at once (make -j) on the same case: it runs once, the other skips."""
    r, count = reproduce_env["reproduce"], reproduce_env["count"]
    case_file = str(reproduce_env["catalogue"] / "ch2" / "cylinder_re100.json")
    procs = [r(paths=[case_file], env_extra={"FAKE_CAPLAB_SLEEP": "1.5"}, background=True) for _ in range(2)]
    outs = [p.communicate(timeout=120) for p in procs]
    assert all(p.returncode == 0 for p in procs), outs
    assert count("ch2/cylinder_re100") == 1
    assert sum("skipped" in o[0] for o in outs) == 1
    leftovers = [p.name for p in (reproduce_env["results"] / "quick").iterdir() if p.name.endswith(".tmp")]
    assert not leftovers


def test_reproduce_bad_usage(reproduce_env, tmp_path):
    r = reproduce_env["reproduce"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert r(paths=[str(empty)]).returncode == 2
    proc = subprocess.run([PYTHON, str(REPO / "scripts" / "reproduce"), "--caplab", str(tmp_path / "nope"),
                           "--fidelity", "quick", "--results", str(tmp_path / "res"), "--no-report",
                           str(reproduce_env["catalogue"])], capture_output=True, text=True)
    assert proc.returncode == 2 and "not found" in proc.stderr


def test_reproduce_jobs(reproduce_env):
    r, count = reproduce_env["reproduce"], reproduce_env["count"]
    proc = r("--jobs", "4")
    assert proc.returncode == 1 and count() == 4
    assert len(re.findall(r"^\[\d/4\]", proc.stdout, re.M)) == 4



@pytest.mark.parametrize("target, folder, fidelity", [
    ("reproduce", "catalogue", "quick"),
    ("reproduce-chapter2", "catalogue/ch2", "standard"),
    ("reproduce-chapter6", "catalogue/ch6", "standard"),
    ("reproduce-extra", "catalogue/extra", "standard"),
])
def test_make_reproduce_targets_run_their_cases(target, folder, fidelity):
    """`make -n`: each reproduce target runs scripts/reproduce on its folder (make skips pattern
    rules for .PHONY targets, which once made `make reproduce-chapter2` do nothing)."""
    out = subprocess.run(["make", "-n", target], cwd=REPO, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    runs = [line for line in out.stdout.splitlines() if "scripts/reproduce" in line]
    assert len(runs) == 1, out.stdout
    assert runs[0].endswith(f" {folder}") and f"--fidelity {fidelity}" in runs[0], runs[0]
