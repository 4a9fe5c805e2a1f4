"""The documentation stays true: the CLI reference is generated from the app, the tutorial runs,
and every test the verification page cites exists."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(mod)
    return mod


def test_cli_reference_is_up_to_date():
    gen = _load(DOCS / "gen_cli.py", "gen_cli")
    current = (DOCS / "cli.md").read_text(encoding="utf-8")
    assert current == gen.render(), "docs/cli.md is out of date: run python docs/gen_cli.py"


def test_cli_reference_lists_every_command_and_option():
    import typer.main

    from geardyn.cli import app

    text = (DOCS / "cli.md").read_text(encoding="utf-8")
    group = typer.main.get_command(app)
    for name, cmd in group.commands.items():
        assert f"## geardyn {name}" in text
        for p in cmd.params:
            for opt in p.opts:
                if opt.startswith("--"):
                    assert f"`{opt}`" in text


def test_tutorial_runs(tmp_path):
    tut = _load(ROOT / "examples" / "tutorial.py", "geardyn_tutorial")
    res = tut.main(tmp_path)
    p = res["physical"]
    assert p["rpm"] == pytest.approx(2400.0) and p["torque_N_m"] == pytest.approx(1500.0)
    assert p["dynamic_factor"] == pytest.approx(p["mesh_force_max_N"] / p["static_force_N"], rel=1e-12)
    assert sum(res["lyapunov"]) == pytest.approx(-0.2, abs=1e-6)  # λ1 + λ2 = −2ξ0
    assert all(Path(f).exists() for f in res["figures"]) and (tmp_path / "sweep.nc").exists()


def _cited_tests(text: str) -> set[tuple[str, str]]:
    return set(re.findall(r"(tests/test_\w+\.py)::(test_\w+)", text))


def test_verification_page_cites_existing_tests():
    text = (DOCS / "verification.md").read_text(encoding="utf-8")
    cited = _cited_tests(text)
    assert len(cited) >= 20
    missing = []
    for path, name in sorted(cited):
        f = ROOT / path
        if not f.exists() or not re.search(rf"^\s*def {name}\(", f.read_text(encoding="utf-8"), re.M):
            missing.append(f"{path}::{name}")
    assert not missing, f"verification.md cites tests that do not exist: {missing}"


def test_docs_link_each_other_and_name_real_commands():
    import typer.main

    from geardyn.cli import app

    commands = set(typer.main.get_command(app).commands)
    quick = (DOCS / "quickstart.md").read_text(encoding="utf-8")
    for page in ("model.md", "cli.md", "verification.md"):
        assert f"({page})" in quick, f"quickstart.md does not link {page}"
    blocks = "\n".join(re.findall(r"```bash\n(.*?)```", quick, re.S))
    used = set(re.findall(r"^\s*geardyn (\w+)", blocks, re.M))
    assert used and used <= commands, f"quickstart.md uses unknown commands: {used - commands}"


def test_quickstart_plots_only_files_an_earlier_command_writes():
    quick = (DOCS / "quickstart.md").read_text(encoding="utf-8")
    lines = [
        ln.split("#")[0].strip() for block in re.findall(r"```bash\n(.*?)```", quick, re.S) for ln in block.splitlines()
    ]
    written: set[str] = set()
    for ln in lines:
        m = re.match(r"geardyn (\w+) .*--out (\S+)", ln)
        plotted = re.match(r"geardyn plot (\S+)", ln)
        if plotted:
            target = Path(plotted.group(1))
            assert str(target.parent) in written, f"quickstart plots {target}, which no earlier command writes"
            assert target.stem in {
                "simulate",
                "response",
                "bifurcation",
                "map",
                "basins",
                "orbit",
                "continuation",
                "lyapunov",
            }, target
        if m and m.group(1) != "plot":
            written.add(m.group(2))


def test_docs_agree_on_the_install_commands():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    quick = (DOCS / "quickstart.md").read_text(encoding="utf-8")
    extras = set(re.findall(r'pip install (?:-e )?"\.\[([^\]]+)\]"', readme + quick))
    assert extras == {"test,dask"}, extras
    assert "Python ≥ 3.11" in readme
