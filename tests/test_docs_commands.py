"""Every command the documentation quotes runs, and the numbers it quotes are what the command prints.

:func:`quoted_commands` collects every ``geardyn …`` line of the shell blocks (fenced or indented) of
``docs/*.md`` and ``README.md`` and every complete command in backticks.  :data:`QUOTED` says, for each,
how the tests run it: as quoted, with shorter settings (fewer points and periods; a synopsis's
``[optional]`` parts left out and its placeholders filled), or why not.  A command added to or changed
in the docs fails :func:`test_every_quoted_command_is_listed` until it is listed here, so the docs
cannot quote a command the tests do not run.  The tests further down compare the numbers of the
docs' text with the output of the command they name (the long runs are marked ``slow``).
"""

from __future__ import annotations

import json
import math
import os
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from geardyn.cli import app

ROOT = Path(__file__).resolve().parents[1]
DOCS = [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]
#: Short integration of the runs whose quoted settings take minutes.
SHORT = {"--transient": "20", "--periods": "8"}


@dataclass(frozen=True)
class Run:
    """How a quoted command is run: option values replaced or added (``set``), placeholders filled
    (``subs``: word → value), commands run before it in the same directory (``before``)."""

    set: dict = field(default_factory=dict)
    subs: dict = field(default_factory=dict)
    before: tuple = ()


AS_QUOTED = Run()


def quoted_commands() -> list[tuple[str, str]]:
    """(file name, command) of every command the docs quote, in the order they appear."""
    out = []
    for f in DOCS:
        if f.name == "cli.md":  # generated from the commands themselves (tests/test_docs.py)
            continue
        text = f.read_text(encoding="utf-8")
        fenced = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
        blocks = [m.group(2) for m in fenced.finditer(text) if m.group(1) in ("bash", "sh", "")]
        blocks += [m.group(0) for m in re.finditer(r"(?:^ {4}.*\n)+", fenced.sub("", text), re.M)]
        for b in blocks:
            for line in re.sub(r"\\\n\s*", " ", b).splitlines():
                if line.strip().startswith("geardyn "):
                    out.append((f.name, " ".join(re.sub(r"\s+#.*$", "", line.strip()).split())))
        for m in re.finditer(r"`(geardyn [a-z]+ [^`]+)`", text):
            cmd = " ".join(m.group(1).split())
            if ("--" in cmd or ".nc" in cmd) and "…" not in cmd and "..." not in cmd:
                out.append((f.name, cmd))
    return out


_FRAGMENT = "not a command: options named in the text"
_BENCH = "a timed benchmark (benchmarks/ runs it, not the tests)"

#: The excitation table of docs/excitation.md's end-to-end example.
_C50 = "geardyn stiffness examples/tooth_crack_50.toml --points 32 --table c50.csv --out c50.nc"
#: Every quoted command: ``AS_QUOTED``, a :class:`Run` with shorter settings, or why the tests do not run it.
QUOTED: dict[str, Run | str] = {
    # analysis.md (the numbers: test_analysis_* below)
    "geardyn lyapunov --omega 0.8 --json": AS_QUOTED,
    "geardyn bifurcation --param omega --start 0.5 --stop 1.5 --num 101 --lyapunov --json": Run(
        {"--num": "5", "--settle": "0", **SHORT}
    ),
    "geardyn response --omega-start 0.3 --omega-stop 1.0 --num 71 --xi0 0.08 --json": Run(
        {"--num": "8", "--settle": "0", **SHORT}
    ),
    # architecture.md
    "geardyn plot FILE.nc": Run(
        subs={"FILE.nc": "arch/simulate.nc"},
        before=("geardyn simulate --omega 0.8 --transient 20 --periods 8 --out arch",),
    ),
    # engineering.md
    "geardyn te FILE.csv --teeth 14,39 [--harmonics 3] [--shaft-orders 2] [--out mesh.toml] [--json]": Run(
        subs={"FILE.csv": "te.csv"}
    ),
    "geardyn runup --rpm-start 1200 --rpm-stop 2400 --duration 2 [--num 21] [--cycles-per-block M] [--out DIR]": Run(
        {"--duration": "0.3", "--num": "3"}
    ),
    "geardyn geometry --config PAIR.toml": Run(subs={"PAIR.toml": "examples/iso10300_sample1.toml"}),
    "geardyn te FILE.csv --teeth z1,z2": Run(subs={"FILE.csv": "te.csv", "z1,z2": "14,39"}),
    "geardyn geometry --config FILE --json": Run(subs={"FILE": "examples/automotive_hypoid_like.toml"}),
    # hb.md
    "geardyn hb --param omega --start 0.3 --stop 1.0 --xi0 0.08 [--harmonics 16] [--period 1] "
    "[--floquet monodromy|hill]": Run({"--harmonics": "6"}),
    "geardyn hb --floquet": _FRAGMENT,
    "geardyn bifurcation --param omega --start 0.5 --stop 1.5 --num 2000 --scheduler tcp://HOST:8786": (
        "needs a running Dask scheduler and worker (tests/test_dask.py runs sweeps on a local cluster)"
    ),
    "geardyn hb --floquet hill": _FRAGMENT,
    "geardyn hb --param omega --start 1.8 --stop 2.2 --xi0 0 --xi1 0 --kappa1 0.2 --fp 0.5 --fe 0 --backlash 1": (
        "tests/test_hb_safety.py runs it and checks the tongue's boundaries against Mathieu's characteristic values"
    ),
    # excitation.md
    "geardyn stiffness examples/tooth_healthy_spur.toml --out out/healthy": AS_QUOTED,
    "geardyn stiffness examples/tooth_crack_50.toml --out out/crack50": AS_QUOTED,
    "geardyn stiffness examples/tooth_helical.toml --out out/helical": AS_QUOTED,
    "geardyn signature examples/tooth_healthy_spur.toml examples/tooth_crack_50.toml --out out/sig": Run(
        {"--revolutions": "4"}
    ),
    "geardyn signature examples/tooth_crack_50.toml --sweep-depths 0,0.1,0.25,0.5,0.75 --out out/sweep": Run(
        {"--revolutions": "4", "--sweep-depths": "0,0.5"}
    ),
    "geardyn signature --system examples/systems/spur_bending_torsional.toml examples/tooth_luo_healthy.toml "
    "examples/tooth_luo_crack50.toml --out out/syssig": Run({"--revolutions": "5", "--rpm": "6000"}),
    "geardyn signature --system examples/systems/spur_crack50.toml --sweep-depths 0,0.1,0.25,0.5 "
    "--out out/syssweep": Run({"--revolutions": "5", "--rpm": "6000", "--sweep-depths": "0,0.5"}),
    "geardyn signature --system examples/systems/spur_healthy.toml --system examples/systems/spur_crack50.toml "
    "--rpm 6000": Run({"--revolutions": "5"}),
    "geardyn stiffness FILE.toml --out x.nc": Run(subs={"FILE.toml": "examples/tooth_healthy_spur.toml"}),
    _C50: AS_QUOTED,
    "geardyn simulate --excitation c50.csv --omega 0.8 --transient 20 --periods 10": Run(before=(_C50,)),
    "geardyn simulate --excitation c50.csv --omega 0.8 --transient 20 --periods 10 --accurate --excitation-evaluation "
    "table": Run(before=(_C50,)),  # as quoted: a shorter transient leaves it unsettled, and settling costs more
    "geardyn lyapunov --excitation c50.csv --omega 0.8 --transient 10 --periods 40": Run(
        {"--transient": "2", "--periods": "20"}, before=(_C50,)
    ),
    "geardyn orbit --excitation c50.csv --omega 0.8": Run({"--transient": "20"}, before=(_C50,)),
    "geardyn continuation --excitation c50.csv --param omega --start 0.8 --stop 0.82 --transient 30": Run(
        {"--stop": "0.801", "--transient": "5", "--dtau": "0.05", "--ds-max": "0.5"}, before=(_C50,)
    ),
    "geardyn bifurcation --excitation c50.csv --param omega --start 0.6 --stop 1.0 --num 5 --transient 20 "
    "--periods 8": Run({"--num": "2"}, before=(_C50,)),
    "geardyn hb --excitation c50.csv --param omega --start 0.8 --stop 0.82": Run({"--max-points": "3"}, before=(_C50,)),
    "geardyn response --method hb --excitation c50.csv --omega-start 0.8 --omega-stop 0.82 --num 5": "about 50 s "
    "of CPU (50 branch points, each with the monodromy of a pinion revolution); tests/test_hb_cycles.py runs "
    "response --method hb with an excitation table over 3 cycles",
    "geardyn runup --excitation c50.csv --omega-start 0.5 --omega-stop 0.7 --tau-duration 4000 --num 5": Run(
        {"--tau-duration": "800", "--num": "0"}, before=(_C50,)
    ),
    "geardyn simulate --system examples/systems/spur_crack50.toml --transient 30 --periods 10": "one forcing "
    "period is about 1e5 RK4 steps (ω = 0.093); tests/test_excitation_system.py loads the file and runs the "
    "same kind of system at ω = 0.8",
    "geardyn response --method hb --omega-start 0.3 --omega-stop 1.0 --xi0 0.08 [--num 71] [--json] [--out DIR]": Run(
        {"--num": "6"}
    ),
    "geardyn hb --system FILE --param omega --start 0.6 --stop 1.2 [--harmonics 12] [--period 1] [--json] "
    "[--out DIR]": Run({"--harmonics": "6"}, subs={"FILE": "examples/systems/paper_torsional.toml"}),
    "geardyn plot hb.nc": Run(before=("geardyn hb --param omega --start 0.5 --stop 0.65 --harmonics 6 --out .",)),
    "geardyn response --method hb": _FRAGMENT,
    "geardyn response --method hb --system": _FRAGMENT,
    # performance.md
    "geardyn bench --workload all --threads 1 --json": _BENCH,
    "geardyn map --x omega --x-start 0.5 --x-stop 0.75 --x-num 1000 --y xi0 --y-start 0.05 --y-stop 0.3 "
    "--y-num 1000 --settle 0 --transient 20 --periods 10 --workers 2 --out DIR": Run(
        {"--x-num": "3", "--y-num": "2"}, subs={"DIR": "perfmap"}
    ),
    "geardyn map --workers 2": _FRAGMENT,
    "geardyn bench --workload W1 --threads 2": _BENCH,
    # the table of the shared coefficient table (its --system is in the table's head; tests/test_ndof_table_reuse.py
    # checks the numbers bit for bit against each point run alone)
    "geardyn basins --nu 1 --nv 1 --transient 0 --periods 2 --settle 0 --workers 1 --json": _BENCH,
    "geardyn simulate --transient 1 --periods 2 --json": _BENCH,
    # quickstart.md (the numbers: test_quickstart_* below)
    "geardyn simulate --omega 0.8": AS_QUOTED,
    "geardyn simulate --omega 0.8 --json": AS_QUOTED,
    "geardyn simulate --omega 1.2 --xi0 0.05 --out sim12": Run(SHORT),
    "geardyn geometry": AS_QUOTED,
    "geardyn geometry --rpm 2400 --torque 1500": AS_QUOTED,
    "geardyn simulate --rpm 2400 --torque 1500": AS_QUOTED,
    "geardyn lyapunov --rpm 2400 --torque 1500 --json": Run({"--transient": "20", "--periods": "40"}),
    "geardyn orbit --rpm 1500 --period 1": AS_QUOTED,
    "geardyn response --rpm-start 900 --rpm-stop 3600 --num 109 --out resp": Run(
        {"--num": "5", "--settle": "0", **SHORT}
    ),
    "geardyn bifurcation --rpm-start 1500 --rpm-stop 2100 --num 61 --mode continue --sweep both": Run(
        {"--num": "4", "--settle": "0", **SHORT}
    ),
    "geardyn map --x omega --rpm-start 900 --rpm-stop 3600 --y xi0 --y-start 0.05 --y-stop 0.2": Run(
        {"--x-num": "3", "--y-num": "2", "--settle": "0", **SHORT}
    ),
    "geardyn geometry --config examples/automotive_hypoid_like.toml": AS_QUOTED,
    "geardyn simulate --config examples/automotive_hypoid_like.toml --json": Run(SHORT),
    "geardyn simulate --config examples/automotive_hypoid_like.toml --rpm 4000 --torque 150": Run(SHORT),
    "geardyn plot resp/response.nc --out figs": AS_QUOTED,
    "geardyn bifurcation --param omega --start 0.5 --stop 1.5 --num 101 --out bif": Run(
        {"--num": "5", "--settle": "0", **SHORT}
    ),
    "geardyn plot bif/bifurcation.nc --config examples/automotive_hypoid_like.toml --out bif_hypoid": AS_QUOTED,
    "geardyn reproduce --out results": "every study with its full settings takes hours; tests/test_reproduce.py "
    "runs them with the quick settings",
    # rattle.md
    "geardyn rattle --system examples/gearbox/rattle_idle.toml --json": Run(
        {"--transient": "3", "--periods": "2", "--dtau": "0.05"}
    ),
    "geardyn rattle --system examples/gearbox/rattle_idle.toml --map-points 9 --scale-points 4 --rpm-start 600 "
    "--rpm-stop 1400 --out rattle": Run(
        {"--map-points": "2", "--scale-points": "1", "--transient": "3", "--periods": "1", "--dtau": "0.05"}
    ),
    "geardyn rattle --fp 0.002 --xi0 0.02 --xi1 0 --kappa1 0.1 --fe 0 --omega 0.5 --torque-order 1/4:0.02 --json": Run(
        {"--transient": "10", "--periods": "2"}
    ),
    "geardyn hb --system": _FRAGMENT,
    "geardyn hb --system examples/systems/ball_bearing.toml --param omega --start 0.5 --stop 0.52 --harmonics 60": (
        "14 points at H = 60 after a simulated start (about 40 s of CPU); tests/test_hb_rolling.py solves the ball "
        "bearing's harmonic balance and runs this command at H = 12"
    ),
    "geardyn rattle --system": _FRAGMENT,
    "geardyn runup --system": _FRAGMENT,
    "geardyn plot rattle_map.nc": Run(
        before=(
            "geardyn rattle --system examples/gearbox/rattle_idle.toml --map-points 2 --scale-points 1 "
            "--transient 3 --periods 1 --dtau 0.05 --out .",
        )
    ),
    # systems.md (the numbers: test_systems_* below)
    "geardyn modes --system examples/systems/paper_bevel_8dof.toml --json": AS_QUOTED,
    "geardyn modes --system examples/systems/paper_bevel_8dof.toml --rpm-max 5000 --out results/bevel8": AS_QUOTED,
    "geardyn modes --system examples/systems/planetary_lin_parker_1999.toml --out results/planetary": AS_QUOTED,
    "geardyn bifurcation --system examples/systems/paper_bevel_8dof.toml --param omega --start 0.5 --stop 1.5 "
    "--num 60 --transient 1000 --periods 32 --out results/bevel8_bif": Run({"--num": "3", "--settle": "0", **SHORT}),
    "geardyn bifurcation --param omega --start 0.5 --stop 1.5 --num 60 --transient 1000 --periods 32 "
    "--out results/onedof_bif": Run({"--num": "3", "--settle": "0", **SHORT}),
    # as quoted: its 300 periods of transient settle on the period-2 orbit, cheaper than 20 and then the exponents
    "geardyn simulate --system examples/systems/paper_torsional.toml --omega 0.8 --accurate --json": AS_QUOTED,
    "geardyn simulate --omega 0.8 --accurate --json": Run(SHORT),
    "geardyn plot results/bevel8/modes.nc": AS_QUOTED,
    # gearbox.md (the numbers: tests/test_gearbox.py)
    "geardyn modes --system examples/gearbox/two_stage_helical.toml --json": AS_QUOTED,
    "geardyn modes --system examples/gearbox/two_stage_helical.toml --rpm-max 3000 --out results/gearbox": AS_QUOTED,
    "geardyn plot results/gearbox/modes.nc": AS_QUOTED,
    "geardyn modes --system examples/gearbox/geared_rotor_gyroscopic.toml --rpm-max 12000 --orders 1 "
    "--out results/gearbox_gyro": AS_QUOTED,
    "geardyn simulate --system examples/gearbox/two_stage_helical.toml --json --transient 1 --periods 1 --dtau 0.05 "
    "--no-classify": "two forcing periods of 1 866 939 RK4 steps on 220 states (about a minute); "
    "tests/test_rolling_bearing.py simulates the ball bearing on its own, tests/test_system_orders.py systems with "
    "torque orders",
    "geardyn simulate --system examples/gearbox/two_stage_helical.toml --rpm 1500 --json": "the default settings "
    "on the 110-DOF gearbox: 5 forcing periods of 9 334 692 RK4 steps (about 20 minutes); tests/test_long_run.py "
    "runs the default simulate of the 12-DOF two-stage file (23/64-19/56, 64 mesh cycles per forcing period)",
    "geardyn signature --system examples/gearbox/two_stage_helical.toml --sensor in_A.x --revolutions 20 "
    "--out results/gearbox_signature": "0.8 s of a 110-DOF gearbox sampled at 1.2 MHz (about two minutes); "
    "tests/test_signature_system.py runs the system signature on the small examples",
    "geardyn response --system examples/gearbox/two_stage_helical.toml --rpm-start 13000 --rpm-stop 17000 --num 5 "
    "--transient 3 --periods 2 --dtau 0.05 --settle 0 --json": "ten points of 5 forcing periods of about 190 000 RK4 "
    "steps on 220 states (minutes); the response sweep is the systems' (tests/test_systems_cli.py)",
    "geardyn runup --system examples/gearbox/two_stage_helical.toml --rpm-start 2000 --rpm-stop 6000 --duration 5 "
    "--num 0 --out results/gearbox_runup": "a ramp of 7700 stage-1 mesh cycles in blocks of one forcing period "
    "(minutes); tests/test_runup_system.py runs the run-up of a system file",
    "geardyn response --system examples/gearbox/two_stage_helical.toml --rpm-start 1000 --rpm-stop 3000 --num 200": (
        "the workload of benchmarks/dask_gearbox.py (200 speeds of the 110-DOF gearbox, minutes); tests/test_dask.py "
        "runs sweeps on a local cluster"
    ),
    "geardyn simulate --system CHAIN_96DOF.toml --omega 0.8 --json": (
        "the workload of benchmarks/ndof_scaling.py --classify (a 96-DOF chain the benchmark generates); "
        "tests/test_kernel_sparse.py checks the leading exponents against the full spectrum"
    ),
    # README.md
    "geardyn simulate --omega 1.2 --out sim12": Run(SHORT),
    "geardyn simulate --rpm 2400 --torque 1500 --json": AS_QUOTED,
    "geardyn response --rpm-start 900 --rpm-stop 3600 --out resp": Run({"--num": "5", "--settle": "0", **SHORT}),
    "geardyn plot resp/response.nc": AS_QUOTED,
}


def argv(command: str, how: Run) -> list[str]:
    """The arguments (after ``geardyn``) of a quoted command run as ``how`` says."""
    text = re.sub(r"\s*\[[^\[\]]*(?:\[[^\[\]]*\][^\[\]]*)*\]", "", command)  # [optional] parts (one nesting level)
    words = [how.subs.get(w, w) for w in shlex.split(text)[1:]]
    for opt, value in how.set.items():
        if opt in words:
            words[words.index(opt) + 1] = value
        else:
            words += [opt, value]
    return words


def _te_record(path: Path) -> None:
    """A synthetic single-flank record of a 14/39 pair: mesh order 14 and a pinion once-per-rev."""
    phi = np.linspace(0.0, 2 * 360.0, 14 * 2 * 64 * 2, endpoint=False)
    te = 2.0 * np.cos(np.radians(14 * phi)) + 0.5 * np.cos(np.radians(phi))
    path.write_text("angle [deg], TE [um]\n" + "".join(f"{a:.6f},{b:.6f}\n" for a, b in zip(phi, te)), encoding="utf-8")


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    """One directory for every quoted command (the docs run them one after the other), with the examples."""
    d = tmp_path_factory.mktemp("docs_commands")
    (d / "examples").symlink_to(ROOT / "examples", target_is_directory=True)
    _te_record(d / "te.csv")
    old = Path.cwd()
    os.chdir(d)
    yield d
    os.chdir(old)


def geardyn(args: list[str]):
    r = CliRunner().invoke(app, args)
    assert r.exit_code == 0, f"geardyn {' '.join(args)}: exit {r.exit_code}\n{r.output}"
    return r


def test_every_quoted_command_is_listed():
    quoted = [c for _, c in quoted_commands()]
    assert len(quoted) > 40
    missing = sorted(set(quoted) - set(QUOTED))
    assert not missing, f"commands quoted in the docs but not run by the tests (list them in QUOTED): {missing}"
    stale = sorted(set(QUOTED) - set(quoted))
    assert not stale, f"QUOTED lists commands the docs no longer quote: {stale}"


def test_docs_send_no_output_into_the_docs():
    """No quoted command writes into docs/ (it would overwrite the tracked figures)."""
    assert [c for _, c in quoted_commands() if re.search(r"--out\s+docs/", c)] == []


#: The ``before`` commands already run in a directory.
_BEFORE_DONE: set = set()


@pytest.mark.parametrize("command", list(dict.fromkeys(c for _, c in quoted_commands())))
def test_quoted_command_runs(command, workdir):
    how = QUOTED[command]
    if isinstance(how, str):
        assert how  # a reason is given
        pytest.skip(how)
    for before in how.before:
        if (workdir, before) not in _BEFORE_DONE:  # its files stay in the one directory of the module
            geardyn(shlex.split(before)[1:])
            _BEFORE_DONE.add((workdir, before))
    geardyn(argv(command, how))


# ------------------------------------------------------------------------------------ quoted numbers
def _doc(name: str) -> str:
    return " ".join((ROOT / "docs" / name).read_text(encoding="utf-8").split())


def _num(pattern: str, text: str) -> list[float]:
    m = re.search(pattern, text)
    assert m, f"the docs no longer say {pattern!r}"
    return [float(g) for g in m.groups()]


def _json(command: str) -> dict:
    return json.loads(geardyn(shlex.split(command)[1:]).stdout)


def test_quickstart_numbers_of_the_operating_point(workdir):
    text = _doc("quickstart.md")
    s = _json("geardyn simulate --rpm 2400 --torque 1500 --json")
    omega, fp = _num(r"# ω = ([\d.]+), f_p = ([\d.]+)", text)
    assert round(s["omega"], 4) == omega and round(s["fp"], 4) == fp
    period, df, fmax, fstat, rms, hz = _num(
        r"runs in a period-(\d+) motion with single-sided impacts: dynamic factor ([\d.]+) \(max mesh force "
        r"([\d.]+) kN against F_p = ([\d.]+) kN\), DTE RMS ([\d.]+) µm, and the strongest line at half the "
        r"mesh order \(([\d.]+) Hz\)",
        text,
    )
    assert s["period"] == period and s["impact"] == "single-sided impact"
    assert round(s["dynamic_factor"], 1) == df
    assert round(s["mesh_force_max_N"] / 1e3, 1) == fmax and round(s["static_force_N"] / 1e3, 1) == fstat
    assert round(s["dte_rms_um"]) == rms
    top = s["spectrum_peaks"][0]
    assert top["order"] == 0.5 and round(top["frequency_Hz"]) == hz


@pytest.mark.slow
def test_quickstart_numbers_of_the_speed_sweep(workdir):
    text = _doc("quickstart.md")
    r = _json("geardyn response --rpm-start 900 --rpm-stop 3600 --num 109 --json")
    up, a, b, down, c, d, lo, hi = _num(
        r"upward jump at ([\d.]+) rpm on the run-up \(between the points at ([\d.]+) and ([\d.]+) rpm\), a "
        r"downward jump at ([\d.]+) rpm on the run-down \(between ([\d.]+) and ([\d.]+) rpm\), and the "
        r"hysteresis interval between the two jumps, rpm \[([\d.]+), ([\d.]+)\]",
        text,
    )
    jumps = {j["sweep"]: j for j in r["jumps"]}
    assert [round(jumps["up"][k], 1) for k in ("rpm", "rpm_from", "rpm_to")] == [up, a, b]
    assert [round(jumps["down"][k], 1) for k in ("rpm", "rpm_from", "rpm_to")] == [down, c, d]
    assert [[round(x, 1) for x in iv] for iv in r["hysteresis_rpm"]] == [[lo, hi]]


def test_analysis_numbers_of_the_lyapunov_exponents(workdir):
    text = _doc("analysis.md")
    l1, e1, l2, e2, total = _num(
        r"\| 0\.8 \| (-?[\d.]+) ± ([\d.]+) \| (-?[\d.]+) ± ([\d.]+) \| (-?[\d.]+) \| "
        r"period-2 \|",
        text.replace("−", "-"),
    )
    s = _json("geardyn lyapunov --omega 0.8 --json")
    assert [round(x, 6) for x in s["exponents"]] == [l1, l2]
    assert [round(x, 6) for x in s["uncertainty"]] == [e1, e2]
    assert round(s["sum"], 10) == total and s["motion"] == "period-2"


def _response_doc():
    text = _doc("analysis.md").replace("−", "-")
    up = _num(r"upward jump between ω = ([\d.]+) and ([\d.]+) \(amplitude ([\d.]+) → ([\d.]+), size ([\d.]+)\)", text)
    down = _num(
        r"downward jump between ω = ([\d.]+) and ([\d.]+) \(amplitude ([\d.]+) → ([\d.]+), size ([\d.]+)\)", text
    )
    return text, up, down


def test_analysis_numbers_of_the_jumps_and_hysteresis(workdir):
    text, up, down = _response_doc()
    cmd = "geardyn response --omega-start 0.3 --omega-stop 1.0 --num 71 --xi0 0.08"
    r = _json(cmd + " --json")
    jumps = {j["sweep"]: j for j in r["jumps"]}
    for want, j in ((up, jumps["up"]), (down, jumps["down"])):
        assert [j["omega_from"], j["omega_to"]] == pytest.approx(want[:2], abs=1e-12)
        assert [round(j["amplitude_from"], 3), round(j["amplitude_to"], 3), round(j["size"], 3)] == want[2:]
    lo, hi = _num(r"hysteresis interval ω \[([\d.]+), ([\d.]+)\], from the midpoint", text)
    assert r["hysteresis"] == [pytest.approx([lo, hi], abs=1e-12)]
    printed = re.search(r"`(hysteresis \(coexisting attractors\): [^`]+)`", text).group(1)
    assert printed in " ".join(geardyn(shlex.split(cmd)[1:]).stdout.split())


@pytest.mark.slow
def test_analysis_numbers_of_the_finer_response(workdir):
    text, _, _ = _response_doc()
    r = _json("geardyn response --omega-start 0.3 --omega-stop 1.0 --num 141 --xi0 0.08 --json")
    a, b, c, d, lo, hi = _num(
        r"With `--num 141` \(step 0\.005\): jumps at ([\d.]+) → ([\d.]+) and ([\d.]+) → "
        r"([\d.]+), interval ω \[([\d.]+), ([\d.]+)\]",
        text,
    )
    jumps = {j["sweep"]: j for j in r["jumps"]}
    assert [jumps["up"]["omega_from"], jumps["up"]["omega_to"]] == pytest.approx([a, b], abs=1e-12)
    assert [jumps["down"]["omega_from"], jumps["down"]["omega_to"]] == pytest.approx([c, d], abs=1e-12)
    assert r["hysteresis"] == [pytest.approx([lo, hi], abs=1e-12)]


def test_systems_numbers_of_the_modes_and_campbell_crossings(workdir):
    text = _doc("systems.md")
    r = _json("geardyn modes --system examples/systems/paper_bevel_8dof.toml --rpm-max 5000 --json")
    rows = re.findall(r"\| ([\d, ]+) \| ([\d.]+)(?: \(pair\))? \| ([\d./ —]+) \|", text)
    assert len(rows) == 6
    f = r["frequencies_hz"]
    for modes, hz, energy in rows:
        for n in (int(x) for x in modes.split(",")):
            assert round(f[n - 1], 2) == float(hz), f"mode {n}"
        if "/" in energy:
            e = r["energy_fractions"][int(modes.split(",")[0]) - 1]
            got = [sum(v for k, v in e.items() if k.startswith(p)) for p in ("pinion", "gear", "mesh")]
            assert [round(x, 3) for x in got] == [float(x) for x in energy.split(" / ")]
    o3, o2, o1 = _num(
        r"the mesh mode 8 is crossed by order 3 at (\d+) rpm, by order 2 at (\d+) rpm and by order 1 "
        r"at (\d+) rpm",
        text,
    )
    mesh = {c["order"]: c["rpm"] for c in r["campbell"]["crossings"] if c["modes"] == [8]}
    assert [round(mesh[k]) for k in (3, 2, 1)] == [o3, o2, o1]
    (below,) = _num(r"All the bearing modes are crossed by order 1 below (\d+) rpm", text)
    bearing = [c["rpm"] for c in r["campbell"]["crossings"] if c["order"] == 1 and c["modes"] != [8]]
    assert max(bearing) < below and math.ceil(max(bearing) / 10) * 10 == below
