"""Bad input to every command is one line on stderr naming the file and the key (or line), exit
2, never a traceback: directories for files, altered trial logs, absurd calibration data, out of
range options, and YAML numbers PyYAML reads as strings."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.simulation.trial import TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN

STACK = load_stack()
BENCH = load(SceneConfig, resolve("scenes/bench.yaml"))


@pytest.fixture(scope="module")
def good_log(tmp_path_factory: pytest.TempPathFactory) -> list[dict[str, Any]]:
    """The records of one real trial's log."""
    spec = TrialSpec("S8-b", "bench", "S8", 314.53e3, 0.45, BENCH_COLUMN, "downward", 0.0, 44e-3, 3)
    out = run_sim_trial(spec, BENCH, STACK, log_dir=tmp_path_factory.mktemp("log"))
    assert out.log_path is not None
    text = Path(out.log_path).read_text(encoding="utf-8")
    return [json.loads(line) for line in text.splitlines()]


def write(path: Path, records: list[dict[str, Any]], garbage_at: int | None = None) -> Path:
    lines = [json.dumps(r) for r in records]
    if garbage_at is not None:
        lines.insert(garbage_at, '{"kind": "sample", "t": ')
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def one_error_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    return lines[0]


def _end(records: list[dict[str, Any]]) -> dict[str, Any]:
    return next(r for r in records if r["kind"] == "end")


def _drop(d: dict[str, Any], key: str) -> None:
    d.pop(key)


ALTERATIONS: dict[str, tuple[Callable[[list[dict[str, Any]]], None], str]] = {
    "end without marks": (lambda rs: _drop(_end(rs), "marks"), "end.marks: missing"),
    "marks null": (lambda rs: _end(rs).update(marks=None), "end.marks: expected an object"),
    "x_buckling a string": (
        lambda rs: _end(rs)["marks"].update(x_buckling="abc"),
        "end.marks.x_buckling: expected a number or null, got 'abc'",
    ),
    "header without sensor": (lambda rs: _drop(rs[0], "sensor"), "header.sensor: missing"),
    "header without poisson": (lambda rs: _drop(rs[0], "poisson"), "header.poisson: missing"),
    "section a string": (lambda rs: rs[0].update(section="EI"), "header.section: expected an"),
    "estimator foo": (lambda rs: rs[0].update(estimator={"foo": 1}), "header.estimator.kind"),
    "unknown spec.kind": (
        lambda rs: rs[0]["spec"].update(kind="tilted"),
        "header.spec.kind: must be one of ['bench', 'robot']",
    ),
    "sensor key a string": (
        lambda rs: rs[0]["sensor"].update(wire_count="four"),
        "sensor.wire_count: expected an integer",
    ),
    "unknown record kind": (lambda rs: rs.insert(3, {"kind": "sampel"}), "line 4: kind: unknown"),
}


@pytest.mark.parametrize("name", sorted(ALTERATIONS))
def test_an_altered_log_is_bad_input_naming_the_key(
    name: str, good_log: list[dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    records = json.loads(json.dumps(good_log))
    alter, expected = ALTERATIONS[name]
    alter(records)
    path = write(tmp_path / "altered.jsonl", records)
    assert main(["replay", str(path)]) == 2
    line = one_error_line(capsys)
    assert str(path) in line
    assert expected in line


def test_a_garbage_sample_line_is_named_not_replayed_as_identical(
    good_log: list[dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path / "garbage.jsonl", good_log, garbage_at=40)
    assert main(["replay", str(path)]) == 2
    assert "damaged log: 1 bad line(s): line 41: not JSON" in one_error_line(capsys)
    assert main(["replay", "--json", str(path)]) == 2
    report = json.loads(capsys.readouterr().out)
    assert report["damaged"] is True
    assert "identical" not in report


def test_the_unaltered_log_replays_identically(
    good_log: list[dict[str, Any]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path / "good.jsonl", good_log)
    assert main(["replay", str(path)]) == 0
    assert capsys.readouterr().out.strip().endswith("identical")


@pytest.mark.parametrize("command", ["replay", "calibrate"])
def test_a_directory_for_a_file_is_bad_input(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([command, str(tmp_path)]) == 2
    assert str(tmp_path) in one_error_line(capsys)


def test_calibration_values_that_overflow_are_bad_input(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "huge.csv"
    path.write_text("strain_ue,shift_pm\n1e300,1\n2e300,2\n3e300,3.1\n", encoding="utf-8")
    assert main(["calibrate", str(path)]) == 2  # was exit 0 with k'_eps = 0
    assert "out of range" in one_error_line(capsys)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["sim", "--workers", "-3"], "--workers: must be >= 1"),
        (["sim", "--limit", "0"], "--limit: must be >= 1"),
        (["sim", "--limit", "-1"], "--limit: must be >= 1"),
        (["emulate", "--seconds", "-1"], "--seconds: must be a finite number > 0"),
    ],
)
def test_out_of_range_options_are_refused(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(argv) == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(
    ("lengths", "message"),
    [("[0]", "must be > 0, got 0"), ("[1e9]", "must be <= 500, got 1000000000.0")],
)
def test_bench_lengths_are_range_checked_naming_the_key(
    lengths: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "s.yaml"
    scene.write_text(f"campaign: {{kind: bench, exposed_lengths_mm: {lengths}}}\n", "utf-8")
    assert main(["sim", "--scene", str(scene), "--out", str(tmp_path / "out")]) == 2
    line = one_error_line(capsys)
    assert f"{scene}: campaign.exposed_lengths_mm[0]: {message}" in line
    assert not (tmp_path / "out").exists()  # refused before any folder is made


def test_yaml_exponent_without_a_dot_is_a_number(tmp_path: Path) -> None:
    from palpate.config.scene import SceneConfig as Scene

    scene = tmp_path / "s.yaml"
    scene.write_text("campaign: {outlier_above_kpa: 3e3}\n", encoding="utf-8")
    assert load(Scene, scene).campaign.outlier_above_kpa == 3000.0
