"""The line an interrupted sweep leaves says what was saved, and nothing that was not."""

from __future__ import annotations

from geardyn.cli import guard
from geardyn.sweep import checkpoints


def test_an_interrupted_sweep_names_only_chunks_that_exist(tmp_path, monkeypatch):
    d = tmp_path / "bifurcation.nc.chunks"
    d.mkdir()
    (d / checkpoints.MANIFEST).write_text("{}")
    monkeypatch.setattr(checkpoints, "_OPEN", {str(d): str(tmp_path / "bifurcation.nc")})
    monkeypatch.setattr(guard.STOP, "message", None, raising=False)
    msg = guard._interrupted_message(KeyboardInterrupt())
    assert "nothing is saved" in msg and "--resume" not in msg and "finished chunks are saved" not in msg
    for i in range(3):
        (d / f"chunk-{i:06d}.npz").write_bytes(b"x")
    msg = guard._interrupted_message(KeyboardInterrupt())
    assert msg.startswith("interrupted: 3 finished chunks saved in") and "--resume" in msg
