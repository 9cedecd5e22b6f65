"""Fuzzing (Hypothesis, seeded by the "ci" profile, a few seconds in all): the frame parser, the
servo emulator's packet handling, the driver's reply handling, the config loader, replay of
mutated trial logs and the checks of mutated scenes take any input and fail only in their
documented ways. The targets and their invariants live in
``benchmarks/fuzztargets.py``, ``fuzzconfig.py`` and ``fuzzfiles.py``; ``palpate bench
--only fuzz`` runs them long."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from benchmarks import fuzzconfig, fuzzfiles
from benchmarks import fuzztargets as fuzz
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.sim.dynamixel import protocol

seeds = st.integers(0, 2**32 - 1)


# -- frame parser ----------------------------------------------------------------------------


@given(st.sampled_from(fuzz.LAYOUTS), st.lists(st.binary(max_size=200), max_size=6))
def test_frame_parser_on_arbitrary_bytes(layout: object, chunks: list[bytes]) -> None:
    fuzz.frame_parser_case(layout, chunks)  # type: ignore[arg-type]


@given(st.sampled_from(fuzz.LAYOUTS), seeds, st.integers(1, 8))
def test_frame_parser_on_damaged_streams_in_any_chunking(
    layout: object, seed: int, pieces: int
) -> None:
    rng = np.random.default_rng(seed)
    data, _ = fuzz.frame_stream(rng, layout, 6)  # type: ignore[arg-type]
    whole = fuzz.frame_parser_case(layout, [data])  # type: ignore[arg-type]
    # however the bytes are cut, the same frames come out
    assert fuzz.frame_parser_case(layout, fuzz.split(data, rng, pieces), whole) == whole  # type: ignore[arg-type]


@given(st.sampled_from(fuzz.LAYOUTS), seeds)
def test_frame_parser_finds_every_frame_of_a_clean_stream(layout: object, seed: int) -> None:
    rng = np.random.default_rng(seed)
    frames = [fuzz.sample_frame(layout, i, rng) for i in range(5)]  # type: ignore[arg-type]
    data = b"".join(frames)
    assert fuzz.frame_parser_case(layout, fuzz.split(data, rng, 4), 5) == 5  # type: ignore[arg-type]


def test_frame_parser_check_fails_on_a_missing_frame() -> None:
    """The invariant checker itself can fail."""
    layout = fuzz.LAYOUTS[0]
    with pytest.raises(fuzz.FuzzFailureError):
        fuzz.frame_parser_case(layout, [b"\x00" * 10], at_least=1)


# -- servo emulator --------------------------------------------------------------------------


@pytest.fixture(scope="module")
def bus() -> fuzz.FaultyBus:
    return fuzz.servo_bus()


@given(data=st.binary(max_size=120))
def test_servo_emulator_on_arbitrary_bytes(bus: fuzz.FaultyBus, data: bytes) -> None:
    fuzz.servo_packet_case(bus, data)


@given(
    servo_id=st.sampled_from([1, 2, 3, 0xFE, 0, 200]),
    instruction=st.integers(0, 255),
    params=st.binary(max_size=24),
)
def test_servo_emulator_on_framed_packets(
    bus: fuzz.FaultyBus, servo_id: int, instruction: int, params: bytes
) -> None:
    fuzz.servo_packet_case(bus, protocol.encode(servo_id, instruction, params))


@given(seeds)
def test_servo_emulator_on_mutated_packets(bus: fuzz.FaultyBus, seed: int) -> None:
    rng = np.random.default_rng(seed)
    fuzz.servo_packet_case(bus, b"".join(fuzz.random_packet(rng) for _ in range(3)))


# -- driver reply handling (dynamixel-sdk over the in-process port) ----------------------------


@pytest.fixture(scope="module")
def driver() -> Iterator[tuple[object, fuzz.FaultyBus]]:
    drv, bus = fuzz.connected_driver()
    yield drv, bus
    drv.close()


@given(op=st.sampled_from(fuzz.DRIVER_OPS), seed=seeds)
def test_driver_on_corrupt_replies(
    driver: tuple[object, fuzz.FaultyBus], op: str, seed: int
) -> None:
    drv, bus = driver
    mutate = fuzz.reply_mutator(np.random.default_rng(seed))
    assert fuzz.driver_reply_case(drv, bus, op, mutate) in ("ok", "transport", "fault")  # type: ignore[arg-type]


@given(op=st.sampled_from(fuzz.DRIVER_OPS), reply=st.binary(max_size=40))
def test_driver_on_arbitrary_reply_bytes(
    driver: tuple[object, fuzz.FaultyBus], op: str, reply: bytes
) -> None:
    drv, bus = driver
    assert fuzz.driver_reply_case(drv, bus, op, lambda real: reply) in (  # type: ignore[arg-type]
        "ok", "transport", "fault",
    )  # fmt: skip


def test_driver_reply_check_sees_a_clean_reply(driver: tuple[object, fuzz.FaultyBus]) -> None:
    drv, bus = driver
    assert fuzz.driver_reply_case(drv, bus, "read_state", lambda real: real) == "ok"  # type: ignore[arg-type]
    assert fuzz.driver_reply_case(drv, bus, "ping", lambda real: b"") == "transport"  # type: ignore[arg-type]


# -- configuration loader --------------------------------------------------------------------

yaml_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=12,
)
SCHEMAS = st.sampled_from([StackConfig, SceneConfig])


@given(SCHEMAS, yaml_values)
def test_config_loader_on_random_mappings(cls: type, data: object) -> None:
    fuzzconfig.config_mapping_case(cls, data)


@pytest.mark.slow
@given(SCHEMAS, seeds)
def test_config_loader_on_mutated_defaults(cls: type, seed: int) -> None:
    rng = np.random.default_rng(seed)
    fuzzconfig.config_mapping_case(
        cls, fuzzconfig.mutate_mapping(fuzzconfig.default_mapping(cls), rng)
    )


@given(SCHEMAS, st.text(max_size=120))
def test_config_loader_on_random_text(
    tmp_path_factory: pytest.TempPathFactory, cls: type, text: str
) -> None:
    path = tmp_path_factory.getbasetemp() / "fuzz.yaml"
    fuzzconfig.config_text_case(cls, text, path)


@pytest.mark.slow
@given(SCHEMAS, seeds)
def test_config_loader_on_mutated_yaml(
    tmp_path_factory: pytest.TempPathFactory, cls: type, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    text = yaml.safe_dump(fuzzconfig.default_mapping(cls))
    fuzzconfig.config_text_case(
        cls, fuzzconfig.mutate_text(text, rng), tmp_path_factory.getbasetemp() / "m.yaml"
    )


def test_config_defaults_load(tmp_path: Path) -> None:
    """The fuzz's starting points are valid, so mutations explore near-valid files."""
    for cls in (StackConfig, SceneConfig):
        assert fuzzconfig.config_mapping_case(cls, fuzzconfig.default_mapping(cls))
        assert fuzzconfig.config_text_case(
            cls, yaml.safe_dump(fuzzconfig.default_mapping(cls)), tmp_path / "d.yaml"
        )


def test_driver_rejects_an_implausible_position_that_passed_the_crc(
    driver: tuple[object, fuzz.FaultyBus],
) -> None:
    """Found by the long fuzz run: a well-formed reply with a position beyond the extended
    position range poisoned the goal step clamp (``write_goals`` then raised ValueError)."""
    drv, bus = driver
    far = bytes(10) + (2**31 - 1).to_bytes(4, "little", signed=True)

    def wild(real: bytes) -> bytes:
        return b"".join(protocol.encode_status(i, 0, far) for i in (1, 2, 3))

    assert fuzz.driver_reply_case(drv, bus, "set_torque", wild) == "transport"  # type: ignore[arg-type]
    assert fuzz.driver_reply_case(drv, bus, "set_torque", lambda r: r) == "ok"  # type: ignore[arg-type]
    assert fuzz.driver_reply_case(drv, bus, "write_goals", lambda r: r) == "ok"  # type: ignore[arg-type]


# -- files a user gives: trial logs (replay) and scene YAML (sim --scene) ----------------------


@pytest.fixture(scope="module")
def valid_logs(tmp_path_factory: pytest.TempPathFactory) -> list[list[str]]:
    return fuzzfiles.sample_logs(tmp_path_factory.mktemp("logs"))


@pytest.mark.slow
@given(seeds)
def test_replay_on_mutated_logs(
    tmp_path_factory: pytest.TempPathFactory, valid_logs: list[list[str]], seed: int
) -> None:
    rng = np.random.default_rng(seed)
    lines = valid_logs[seed % len(valid_logs)]
    data = fuzzfiles.mutate_log(lines, rng)
    outcome = fuzzfiles.replay_case(data, tmp_path_factory.getbasetemp() / "fuzz.jsonl")
    assert outcome in ("identical", "different", "truncated", "damaged", "bad input")


def test_replay_fuzz_starts_from_logs_that_replay_identically(
    tmp_path: Path, valid_logs: list[list[str]]
) -> None:
    for lines in valid_logs:
        data = ("\n".join(lines) + "\n").encode()
        assert fuzzfiles.replay_case(data, tmp_path / "ok.jsonl") == "identical"
        assert fuzzfiles.replay_case(data[:-200], tmp_path / "cut.jsonl") == "truncated"


@given(seeds)
def test_sim_scene_checks_on_mutated_scenes(
    tmp_path_factory: pytest.TempPathFactory, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    texts = fuzzfiles.scene_texts()
    text = fuzzfiles.mutate_scene(texts[seed % len(texts)], rng)
    path = tmp_path_factory.getbasetemp() / "scene.yaml"
    assert fuzzfiles.scene_case(text, path) in ("accepted", "refused")


def test_scene_fuzz_starts_from_scenes_that_plan(tmp_path: Path) -> None:
    for text in fuzzfiles.scene_texts():
        assert fuzzfiles.scene_case(text, tmp_path / "s.yaml") == "accepted"


def test_yaml_alias_bombs_and_deep_nesting_are_refused(tmp_path: Path) -> None:
    """A few lines whose aliases expand to 9**10 values, and brackets nested 5,000 deep: a
    ConfigError each, not a hang or a RecursionError."""
    bomb = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    bomb += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 10)]
    path = tmp_path / "s.yaml"
    assert fuzzfiles.scene_case("\n".join(bomb), path) == "refused"
    assert fuzzfiles.scene_case("[" * 5000 + "]" * 5000, path) == "refused"
