"""The lockstep harness on its example design: packing, stimulus forms, both paths, injected bugs, waveforms."""

from __future__ import annotations

import functools
import shutil
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.errors import Supi3Error
from supi3.verif import (
    EventLog,
    Lockstep,
    LockstepMismatchError,
    Pin,
    PinSpecError,
    WordLayout,
    first_mismatch,
    model_trace,
    react,
    run_lockstep_batch,
    stimulus_array,
)
from supi3.verif.amaranth_sim import run_amaranth_sim
from supi3.verif.example import ShiftCounter, ShiftCounterModel
from support import VerilatorBuild

CYCLES = 4000
BUG_DIN = 0xA5


class WrongLoadModel(ShiftCounterModel):
    """Injected model bug: loading 0xA5 loads 0xA4. Module-level, so the simulator process can unpickle it."""

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        outputs = super().step(inputs)
        if inputs["load"] and inputs["din"] == BUG_DIN:
            self.count = BUG_DIN - 1
        return outputs


class WideOutputModel(ShiftCounterModel):
    """Model bug of another kind: an output value wider than its pin."""

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        cycle = self.cycle
        outputs = super().step(inputs)
        outputs["count"] |= 0x100 if cycle == 7 else 0
        return outputs


def random_stimulus(cycles: int, seed: int) -> np.ndarray:
    """Random example stimulus: columns en, load (rare), din, sin, rd."""
    rng = np.random.default_rng(seed)
    stimulus = rng.integers(0, 2, (cycles, 5))
    stimulus[:, 1] = rng.random(cycles) < 0.05
    stimulus[:, 2] = rng.integers(0, 256, cycles)
    return stimulus


def first_bug_cycle(stimulus: np.ndarray) -> int:
    """The cycle after the first load of 0xA5, where the wrong model's count first differs."""
    loads = np.flatnonzero((stimulus[:, 1] == 1) & (stimulus[:, 2] == BUG_DIN))
    return int(loads[0]) + 1


@pytest.fixture(scope="session")
def build_root(verilator_build: VerilatorBuild) -> Path:
    return verilator_build("lockstep")


@pytest.fixture(scope="session")
def bench(build_root: Path) -> Lockstep:
    lockstep = Lockstep(ShiftCounter, ShiftCounterModel, build_dir=build_root)
    lockstep.prepare()
    return lockstep


@pytest.fixture(scope="session")
def buggy(bench: Lockstep) -> Lockstep:
    return Lockstep(ShiftCounter, WrongLoadModel, build_dir=bench.build_dir)


@pytest.fixture(scope="session")
def bug_stimulus() -> np.ndarray:
    stimulus = random_stimulus(CYCLES, seed=7)
    stimulus[1500] = (1, 1, BUG_DIN, 0, 0)
    assert first_bug_cycle(stimulus) <= 1501
    return stimulus


@pytest.fixture(scope="session")
def per_cycle_bug(buggy: Lockstep, bug_stimulus: np.ndarray) -> LockstepMismatchError:
    with pytest.raises(LockstepMismatchError) as caught:
        buggy.run(bug_stimulus)
    return caught.value


# Layout and stimulus, no simulator ---------------------------------------------------------------------------------


def test_layout_keeps_fields_inside_words() -> None:
    layout = WordLayout.of(ShiftCounterModel())
    assert layout.output_names == ["count", "sr", "acc", "zero", "match", "bus_oe", "bus"]
    for field in (*layout.in_fields, *layout.out_fields):
        assert (field.width > 32 and field.shift == 0) or field.shift + field.width <= 32
    acc = layout.out_fields[2]
    assert (acc.word, acc.shift) == (1, 0)
    assert layout.out_fields[3].word == 3


@given(st.lists(st.integers(0, 2**64 - 1), min_size=7, max_size=7))
def test_words_round_trip(values: list[int]) -> None:
    layout = WordLayout(
        [Pin("a", 3)], [Pin("x", 5), Pin("y", 64), Pin("z", 31), Pin("w", 33), Pin("t", 2, tristate=True)]
    )
    row = [value & field.mask for value, field in zip(values, layout.out_fields, strict=False)]
    words = np.zeros((1, layout.out_words), dtype=np.uint32)
    packed = sum(value << field.offset for value, field in zip(row, layout.out_fields, strict=True))
    for index in range(layout.out_words):
        words[0, index] = (packed >> (32 * index)) & 0xFFFF_FFFF
    assert layout.output_trace(words)[0].tolist() == row
    assert layout.output_words(np.array([row], dtype=np.uint64)).tolist() == words.tolist()
    assert layout.pack_outputs(row) == words[0].tolist()
    assert layout.unpack_outputs(packed) == tuple(row)
    assert layout.matches(row, packed)


@given(st.lists(st.lists(st.integers(0, 2**64 - 1), min_size=5, max_size=5), min_size=1, max_size=4))
def test_input_words_place_every_field(rows: list[list[int]]) -> None:
    pins = [Pin("a", 3), Pin("b", 64), Pin("c", 31), Pin("d", 33), Pin("e", 1)]
    layout = WordLayout(pins, [Pin("x")])
    stimulus = np.array([[v & pin.mask for v, pin in zip(row, pins, strict=True)] for row in rows], dtype=np.uint64)
    words = layout.input_words(stimulus)
    for row, packed_row in zip(stimulus.tolist(), words.tolist(), strict=True):
        packed = sum(value << field.offset for value, field in zip(row, layout.in_fields, strict=True))
        assert packed_row == [(packed >> (32 * index)) & 0xFFFF_FFFF for index in range(layout.in_words)]


@settings(max_examples=200)
@given(st.data())
def test_word_compare_agrees_with_signal_compare(data: st.DataObject) -> None:
    layout = WordLayout([Pin("a")], [Pin("x", 5), Pin("y", 40, tristate=True), Pin("t", 2, tristate=True)])
    cycles = data.draw(st.integers(1, 6))
    signal = st.tuples(*(st.integers(0, field.mask) for field in layout.out_fields))
    expected = np.array(data.draw(st.lists(signal, min_size=cycles, max_size=cycles)), dtype=np.uint64)
    actual = expected.copy()
    for cycle, index, value in data.draw(st.lists(st.tuples(st.integers(0, cycles - 1), st.integers(0, 4),
                                                            st.integers(0, 2**40 - 1)), max_size=4)):
        actual[cycle, index] = value & layout.out_fields[index].mask
    found = first_mismatch(layout, expected, actual)
    assert layout.first_word_mismatch(layout.output_words(expected), layout.output_words(actual)) == found


def test_tristate_value_compared_only_while_enabled() -> None:
    layout = WordLayout([], [Pin("d", 8, tristate=True)])
    assert layout.output_names == ["d_oe", "d"]
    disabled, enabled = (0, 0x12), (1, 0x12)
    assert layout.matches(disabled, 0x34 << 1)
    assert not layout.matches(enabled, 1 | 0x34 << 1)
    assert layout.first_difference(enabled, (1, 0x34)) == 1
    assert layout.first_difference(disabled, (1, 0x12)) == 0
    expected = np.array([[0, 0x12], [1, 0x12], [1, 0x12]], dtype=np.uint64)
    actual = np.array([[0, 0x99], [1, 0x12], [1, 0x13]], dtype=np.uint64)
    assert first_mismatch(layout, expected, actual) == (2, 1)


def test_stimulus_forms_agree() -> None:
    inputs = ShiftCounterModel.inputs
    rows = [{"en": 1, "din": 3}, {"rd": 1}, {"en": 0, "din": 255}]
    expected = [[1, 0, 3, 0, 0], [1, 0, 3, 0, 1], [0, 0, 255, 0, 1]]
    assert stimulus_array(rows, inputs).tolist() == expected
    assert stimulus_array(iter(rows), inputs).tolist() == expected
    assert stimulus_array(np.array(expected), inputs).tolist() == expected

    def endless() -> Iterator[dict[str, int]]:
        while True:
            yield {"en": 1}

    assert stimulus_array(endless(), inputs, max_cycles=10).shape == (10, 5)


@pytest.mark.parametrize(
    ("stimulus", "message"),
    [
        ([{"nope": 1}], "'nope' is not an input pin"),
        ([{"din": 256}], "'din' = 0x100 exceeds 8 bits"),
        (np.zeros((3, 4), dtype=int), r"shape \(cycles, 5\)"),
        (np.full((3, 5), -1), "negative"),
    ],
)
def test_bad_stimulus_is_named(stimulus: object, message: str) -> None:
    with pytest.raises(PinSpecError, match=message) as caught:
        stimulus_array(stimulus, ShiftCounterModel.inputs)  # type: ignore[arg-type]
    assert isinstance(caught.value, Supi3Error)


def test_pin_rules() -> None:
    with pytest.raises(PinSpecError, match="width must be an integer from 1 to 64"):
        Pin("x", 65)
    with pytest.raises(PinSpecError, match="identifier"):
        Pin("x y")
    with pytest.raises(PinSpecError, match="unique"):
        WordLayout([Pin("a")], [Pin("a")])
    with pytest.raises(PinSpecError, match="only output pins"):
        WordLayout([Pin("a", tristate=True)], [Pin("b")])


def test_event_log_keeps_the_last_events() -> None:
    log = EventLog(depth=2)
    for cycle in range(3):
        log.add(cycle, "write {:#04x}", cycle)
    assert log.recent() == ["cycle 1: write 0x01", "cycle 2: write 0x02"]


def test_design_must_expose_the_model_pins(build_root: Path) -> None:
    class ExtraPinModel(ShiftCounterModel):
        outputs = (*ShiftCounterModel.outputs, Pin("extra"))

    with pytest.raises(PinSpecError, match="no attribute 'extra'"):
        Lockstep(ShiftCounter, ExtraPinModel, build_dir=build_root)


def test_react_feeds_model_outputs_back() -> None:
    def agent(cycle: int, outputs: Mapping[str, int] | None) -> dict[str, int]:
        # Read the bus whenever the counter was odd on the previous cycle.
        return {"en": 1, "din": cycle & 0xFF, "rd": int(outputs is not None and outputs["count"] & 1)}

    stimulus = react(ShiftCounterModel, agent, 50)
    trace = model_trace(ShiftCounterModel(), stimulus, WordLayout.of(ShiftCounterModel()))
    assert stimulus[1:, 4].tolist() == (trace[:-1, 0] & np.uint64(1)).tolist()


# Per-cycle path (cocotb) -------------------------------------------------------------------------------------------


def test_per_cycle_passes_on_a_correct_model(bench: Lockstep) -> None:
    result = bench.run(random_stimulus(CYCLES, seed=1))
    assert (result.cycles, result.path, result.simulator) == (CYCLES, "per-cycle", "verilator")
    assert bench.run([]).cycles == bench.run_batch([]).cycles == 0


def test_per_cycle_catches_an_injected_model_bug(
    per_cycle_bug: LockstepMismatchError, bug_stimulus: np.ndarray
) -> None:
    error = per_cycle_bug
    cycle = first_bug_cycle(bug_stimulus)
    assert (error.cycle, error.pin, error.expected, error.actual) == (cycle, "count", BUG_DIN - 1, BUG_DIN)
    assert f"cycle {cycle - 1}: load 0xa5" in error.events
    assert f"cycle {cycle}: output 'count' expected 0xa4 (model), got 0xa5 (RTL)" in str(error)
    assert error.vcd is not None and error.vcd.exists() and str(error.vcd) in str(error)
    waveform = error.vcd.read_text()
    for scope in ("inputs", "model", "rtl", "harness"):
        assert f"$scope module {scope} $end" in waveform
    assert f"#{cycle * 10}\n" in waveform and f"#{(cycle - 63) * 10}\n" in waveform


def test_per_cycle_runs_under_icarus(
    build_root: Path, buggy: Lockstep, bug_stimulus: np.ndarray, per_cycle_bug: LockstepMismatchError
) -> None:
    if shutil.which("iverilog") is None:
        pytest.skip("iverilog not installed (apt-get install iverilog): the Icarus path is optional")
    lockstep = Lockstep(ShiftCounter, ShiftCounterModel, build_dir=build_root)
    result = lockstep.run(random_stimulus(500, seed=2), simulator="icarus")
    assert (result.cycles, result.simulator) == (500, "icarus")
    with pytest.raises(LockstepMismatchError) as caught:
        buggy.run(bug_stimulus, simulator="icarus")
    fields = ("cycle", "pin", "expected", "actual", "events")
    assert [getattr(caught.value, name) for name in fields] == [getattr(per_cycle_bug, name) for name in fields]
    errors = (caught.value, per_cycle_bug)
    waveforms = [error.vcd.read_text().split("$enddefinitions")[1] for error in errors if error.vcd]
    assert len(waveforms) == 2 and waveforms[0] == waveforms[1]


@pytest.mark.usefixtures("bench")
def test_model_factory_must_be_picklable(build_root: Path) -> None:
    lockstep = Lockstep(ShiftCounter, lambda: ShiftCounterModel(), build_dir=build_root)
    with pytest.raises(PinSpecError, match="picklable"):
        lockstep.run([{"en": 1}])


# Batch path --------------------------------------------------------------------------------------------------------


def test_batch_passes_on_a_correct_model(bench: Lockstep) -> None:
    result = bench.run_batch(random_stimulus(100_000, seed=3))
    assert (result.cycles, result.path) == (100_000, "batch")


def test_batch_agrees_with_per_cycle_on_a_bug(
    buggy: Lockstep, bug_stimulus: np.ndarray, per_cycle_bug: LockstepMismatchError
) -> None:
    with pytest.raises(LockstepMismatchError) as caught:
        buggy.run_batch(bug_stimulus)
    batch = caught.value
    fields = ("cycle", "pin", "expected", "actual", "events")
    assert [getattr(batch, name) for name in fields] == [getattr(per_cycle_bug, name) for name in fields]
    assert batch.path == "batch" and batch.vcd is not None and per_cycle_bug.vcd is not None
    waveforms = [error.vcd.read_text().split("$enddefinitions")[1] for error in (batch, per_cycle_bug) if error.vcd]
    assert waveforms[0] == waveforms[1]


@pytest.mark.usefixtures("bench")
def test_model_output_wider_than_its_pin_is_named(build_root: Path) -> None:
    lockstep = Lockstep(ShiftCounter, WideOutputModel, build_dir=build_root)
    for run in (lockstep.run_batch, lockstep.run):
        with pytest.raises(PinSpecError, match="cycle 7: model output 'count' does not fit in 8 bits"):
            run(random_stimulus(20, seed=4))


@pytest.mark.usefixtures("bench")
def test_no_vcd_when_not_asked(build_root: Path, bug_stimulus: np.ndarray) -> None:
    lockstep = Lockstep(ShiftCounter, WrongLoadModel, build_dir=build_root, vcd_on_mismatch=False)
    with pytest.raises(LockstepMismatchError) as caught:
        lockstep.run_batch(bug_stimulus)
    assert caught.value.vcd is None


cycle_inputs = st.fixed_dictionaries(
    {},
    optional={
        "en": st.integers(0, 1),
        "load": st.integers(0, 1),
        "din": st.one_of(st.just(BUG_DIN), st.integers(0, 255)),
        "sin": st.integers(0, 1),
        "rd": st.integers(0, 1),
    },
)


@settings(max_examples=25)
@given(st.lists(cycle_inputs, min_size=1, max_size=300))
def test_batch_random_scenarios(bench: Lockstep, scenario: list[dict[str, int]]) -> None:
    assert bench.run_batch(scenario).cycles == len(scenario)


@settings(max_examples=25)
@given(st.lists(cycle_inputs, min_size=1, max_size=300))
def test_batch_finds_the_injected_bug_whenever_it_shows(buggy: Lockstep, scenario: list[dict[str, int]]) -> None:
    stimulus = stimulus_array(scenario, ShiftCounterModel.inputs)
    loads = np.flatnonzero((stimulus[:, 1] == 1) & (stimulus[:, 2] == BUG_DIN))
    shows = loads.size > 0 and loads[0] + 1 < len(scenario)
    if not shows:
        assert buggy.run_batch(stimulus).cycles == len(scenario)
        return
    with pytest.raises(LockstepMismatchError) as caught:
        buggy.run_batch(stimulus)
    assert (caught.value.cycle, caught.value.pin) == (int(loads[0]) + 1, "count")


@pytest.mark.usefixtures("bench")
def test_partial_factories_are_accepted(build_root: Path) -> None:
    design, model = functools.partial(ShiftCounter), functools.partial(ShiftCounterModel)
    assert run_lockstep_batch(design, model, random_stimulus(1000, seed=5), build_dir=build_root).cycles == 1000


# Amaranth's simulator --------------------------------------------------------------------------------------------


def test_amaranth_sim_passes_and_agrees_on_a_bug(
    tmp_path: Path, bug_stimulus: np.ndarray, per_cycle_bug: LockstepMismatchError
) -> None:
    assert run_amaranth_sim(ShiftCounter, ShiftCounterModel, random_stimulus(500, seed=6)).cycles == 500
    with pytest.raises(LockstepMismatchError) as caught:
        run_amaranth_sim(ShiftCounter, WrongLoadModel, bug_stimulus, vcd_dir=tmp_path)
    fields = ("cycle", "pin", "expected", "actual", "events")
    assert [getattr(caught.value, name) for name in fields] == [getattr(per_cycle_bug, name) for name in fields]
    assert caught.value.vcd is not None and caught.value.vcd.parent == tmp_path
