"""The tip force grating through the sensor chain (issue 28): the frame protocol's revision 1.1
(old frames and layouts unchanged), the emulated board's channel, the zero and the temperature
compensation, and the sensor files that cannot work."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.config.loader import ConfigError, from_mapping
from palpate.config.scene import FidelityConfig
from palpate.config.schema import FbgConfig, StackConfig, TipGratingConfig
from palpate.estimation.detect.contact import difference_sigma
from palpate.sensor.reader import FrameReader
from palpate.sensor.tipforce import TipForceChain
from palpate.sim.board import BoardEmulator, BoardSample
from palpate.sim.clock import VirtualClock
from palpate.sim.readout import TipReadout
from palpate.wire.frame import OPTION_TIP, decode, encode, frame_from_si, layout_of, parse_header
from palpate.wire.frameblock import decode_block

PEAKS = [1.530e-6, 1.535e-6, 1.540e-6]


def test_a_frame_without_the_tip_grating_is_a_revision_1_0_frame() -> None:
    frame = frame_from_si(7, 1.0, -3, PEAKS, reference=1.525e-6)
    data = encode(frame)
    assert data[4] == 0x01
    assert len(data) == 28 + 12 + 4
    assert decode(data) == frame
    assert frame.tip_fm is None
    assert frame.tip is None


def test_the_tip_grating_follows_every_other_field() -> None:
    frame = frame_from_si(7, 1.0, -3, PEAKS, reference=1.525e-6, force=0.25, tip=1.5601e-6)
    data = encode(frame)
    layout = parse_header(data[:6])
    assert layout == layout_of(3, True, True, True)
    assert data[4] == 0x01 | 0x02 | OPTION_TIP
    assert len(data) == 28 + 12 + 4 + 4 + 4
    assert int.from_bytes(data[-8:-4], "little") == frame.tip_fm  # just before the CRC
    back = decode(data)
    assert back == frame
    assert back.tip == pytest.approx(1.5601e-6, abs=1e-15)
    block, stats = decode_block(data * 3, layout)
    assert len(block) == 3
    assert stats.rejected == 0
    assert block.frame(2) == frame


def test_a_frame_with_the_tip_grating_is_rejected_by_a_layout_without_it() -> None:
    data = encode(frame_from_si(1, 0.0, 0, PEAKS, tip=1.56e-6))
    with pytest.raises(ValueError, match="header"):
        decode(data, layout_of(3))


def tip_config(**kw: object) -> TipGratingConfig:
    return TipGratingConfig(**kw)  # type: ignore[arg-type]


def test_the_chain_reads_the_load_and_takes_the_drift_out() -> None:
    tip = tip_config(sensitivity_pm_per_mn=8.0, temperature_coefficient_pm_per_degc=12.0)
    fbg = FbgConfig(reference_wavelength_nm=1525.0, temperature_coefficient_pm_per_degc=10.0)
    fidelity = FidelityConfig(fbg_noise_pm=1.0)
    readout = TipReadout(tip, fidelity)
    rng = np.random.default_rng(3)
    rest = [readout.read(0.0, 0.0, rng) for _ in range(200)]
    refs = 1.525e-6 + rng.normal(0.0, 1e-12, 200)
    chain = TipForceChain.from_config(tip, fbg).zeroed(rest, refs)
    # 1 pm on the tip grating and 1 pm on the reference it is compensated with, at 8 pm/mN
    assert chain.noise() == pytest.approx(2**0.5 * 1e-12 / 8e-9, rel=0.15)
    drift = 2.0  # deg C: 24 pm on the tip grating, 3 mN uncompensated
    loads = np.linspace(0.0, 18e-3, 50)
    read = [chain.force(readout.read(f, drift, rng), 1.525e-6 + 10e-12 * drift) for f in loads]
    err = np.asarray(read) - loads
    assert abs(err.mean()) < 0.1e-3
    assert err.std() < 0.2e-3
    uncompensated = TipForceChain(tip.sensitivity, 0.0, False, chain.zero)
    assert uncompensated.force(readout.read(0.0, drift, rng)) == pytest.approx(3e-3, abs=0.5e-3)
    assert difference_sigma(read) == pytest.approx(0.125e-3, rel=0.3)  # the reference was exact


def test_past_its_range_the_element_reads_no_more() -> None:
    tip = tip_config(sensitivity_pm_per_mn=8.0, range_mn=20.0)
    readout = TipReadout(tip, FidelityConfig(fbg_noise_pm=0.0))
    rng = np.random.default_rng(0)
    assert readout.read(50e-3, 0.0, rng) == readout.read(20e-3, 0.0, rng)


def test_the_emulated_board_sends_the_tip_grating_over_a_pty() -> None:
    layout = layout_of(3, True, False, True)
    clock = VirtualClock()
    sample = BoardSample(PEAKS, reference=1.525e-6, tip=1.5602e-6)
    with (
        BoardEmulator(lambda t: sample, layout, rate_hz=1000, clock=clock) as emu,
        FrameReader(emu.port, layout, clock=clock) as reader,
    ):
        clock.advance(0.0095)
        frames = reader.read_frames(9, timeout_s=10.0)
    assert len(frames) == 9
    assert all(f.tip_fm == round(1.5602e-6 / 1e-15) for f in frames)
    assert all(f.reference == pytest.approx(1.525e-6, abs=1e-15) for f in frames)


@pytest.mark.parametrize(
    ("sensor", "fbg", "board", "key"),
    [
        ({"tip_grating": {"sensitivity_pm_per_mn": 0}}, {}, {}, "sensitivity_pm_per_mn"),
        ({"tip_grating": {}}, {}, {"has_reference": True}, "reference_wavelength_nm"),
        ({"tip_grating": {}}, {"reference_wavelength_nm": 1525}, {}, "has_reference"),
        ({"tip_grating": {"range_mn": -1}}, {}, {}, "range_mn"),
    ],
)
def test_a_tip_grating_that_cannot_work_is_refused_naming_the_key(
    sensor: dict[str, object], fbg: dict[str, object], board: dict[str, object], key: str
) -> None:
    with pytest.raises(ConfigError, match=key) as err:
        from_mapping(StackConfig, {"sensor": sensor, "fbg": fbg, "board": board}, "lung.yaml")
    assert "lung.yaml" in str(err.value)


def test_a_zero_taken_again_on_a_few_frames_keeps_the_larger_zeros_noise() -> None:
    tip = tip_config(temperature_compensation="none")
    chain = TipForceChain.from_config(tip, FbgConfig())
    rng = np.random.default_rng(5)
    first = chain.zeroed(1.56e-6 + rng.normal(0.0, 1e-12, 200))
    again = first.zeroed(1.56e-6 + 3e-12 + rng.normal(0.0, 1e-12, 8))
    assert again.noise() == first.noise()  # the noise of 200 frames, not of 8
    assert again.force(1.56e-6 + 3e-12) == pytest.approx(0.0, abs=0.1e-3)  # the new offset
