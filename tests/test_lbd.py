"""The counter telegram on the line, bit period by bit period (supi3.lbd; manual 2.2.2, docs/interbus.md "Counter
telegram", BK-6, BK-30 to BK-33): exhaustive over every data and status telegram in and out of a frame, silence and
the generator, dropped telegrams, the transaction-level rule (wire.count_on) bit for bit, chains of devices behind
every break against ring.lbd_count (saturation included), and hostile inputs."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import pytest

from supi3.errors import ArgumentError
from supi3.interbus import wire
from supi3.interbus.ring import BranchKind, lbd_count
from supi3.interbus.wire import Cycle
from supi3.lbd import (
    COUNTER_SILENCE_BITS,
    GENERATED_TELEGRAM,
    IDLE_BIT,
    OUTPUT_SLOTS,
    CounterBit,
    CounterState,
    clocks_per_bit,
    counter_step,
    sample_phase,
    send_countdown,
)
from support import bad, lbd_breaks

S = COUNTER_SILENCE_BITS
N = wire.DATA_TELEGRAM_BITS
HEADER_MASK = 0b1111
COUNTER_HEADER = wire.counter_telegram(1) & HEADER_MASK


def run(levels: Sequence[int], state: CounterState | None = None) -> tuple[CounterState, list[CounterBit]]:
    """The bit periods ``levels`` through the spec from ``state`` (reset by default)."""
    state = CounterState() if state is None else state
    sent = []
    for level in levels:
        state, bit = counter_step(state, level)
        sent.append(bit)
    return state, sent


def bits(word: int, length: int = N) -> list[int]:
    return [(word >> i) & 1 for i in range(length)]


def word_of(sent: Sequence[CounterBit]) -> int:
    return sum(bit.out << i for i, bit in enumerate(sent))


def incremented(byte: int) -> int:
    """The byte sent for a received counter telegram byte, by arithmetic (BK-31): count + 1 modulo 64, the carry
    out sets bit 6."""
    count = byte & wire.COUNTER_MAX
    return (byte & 0xC0) | ((count + 1) & wire.COUNTER_MAX) | (0x40 if count == wire.COUNTER_MAX else 0)


# -- every telegram, in and out of a frame -------------------------------------------------------------------------


def test_every_data_telegram_in_and_out_of_a_frame() -> None:
    """All 1,024 data telegrams (byte x select x control) with and without an open frame: only an ID check telegram
    outside a frame is a counter telegram; it goes out incremented (count bits and saturation mark, driven from bit
    4), its count is kept when its byte is a counter byte; every other telegram goes out unchanged, undriven. The
    frame opens on a data-sequence telegram and stays open through check telegrams."""
    for byte, cycle, check, frame in itertools.product(range(256), Cycle, (False, True), (0, 1)):
        word = wire.data_telegram(byte, cycle, check)
        state, sent = run(bits(word), CounterState(frame=frame, counted=7))
        counter = cycle is Cycle.ID and check and not frame
        assert (word & HEADER_MASK == COUNTER_HEADER) == (cycle is Cycle.ID and check)
        if counter:
            assert word_of(sent) == wire.data_telegram(incremented(byte), cycle, check)
            assert [bit.drive for bit in sent] == [0] * wire.POS_DATA + [1] * (N - wire.POS_DATA)
            count = wire.counter_count(byte)
            assert state.counted == (7 if count is None else count)
            assert [bit.seen for bit in sent] == [0] * (N - 1) + [int(count is not None)]
        else:
            assert word_of(sent) == word
            assert not any(bit.drive or bit.seen for bit in sent)
            assert state.counted == 7
        assert state.frame == (int(not check) if not frame else 1)
        assert (state.bit, state.quiet, state.gen, state.drop) == (IDLE_BIT, 0, IDLE_BIT, 0)


def test_status_telegrams_close_the_frame_and_pass() -> None:
    for cycle, check, frame in itertools.product(Cycle, (False, True), (0, 1)):
        word = wire.status_telegram(cycle, check)
        state, sent = run(bits(word, wire.STATUS_TELEGRAM_BITS), CounterState(frame=frame))
        assert word_of(sent) == word and not any(bit.drive for bit in sent)
        assert (state.frame, state.bit) == (0, IDLE_BIT)


def test_count_on_is_the_line_rule_bit_for_bit() -> None:
    """wire.count_on (the transaction level) sends exactly what a device sends on the line, for every counter
    telegram (saturated ones too), and count_on(None) is the generated telegram."""
    for byte in range(256):
        word = wire.data_telegram(byte, Cycle.ID, True)
        if wire.decode_counter_telegram(word) is None:
            continue
        assert word_of(run(bits(word))[1]) == wire.count_on(word)
    assert wire.count_on(None) == GENERATED_TELEGRAM == wire.counter_telegram(1)


def test_counts_saturate_and_stay_saturated() -> None:
    word = wire.counter_telegram(62)
    counts = []
    for _ in range(4):
        word = wire.count_on(word)
        counts.append(wire.decode_counter_telegram(word))
    assert counts == [wire.COUNTER_MAX] * 4
    assert wire.count_on(wire.counter_telegram(wire.COUNTER_MAX)) >> wire.POS_DATA & 0xC0 == wire.COUNTER_SATURATED_MARK


def test_stop_bit_at_start_level_starts_the_next_telegram() -> None:
    """M16: the stop bit at start level is the next telegram's start bit, on the same grid; the counter telegram
    it ended is not counted."""
    word = wire.counter_telegram(9) & ~(1 << (N - 1))
    state, sent = run(bits(word) + bits(wire.counter_telegram(4))[1:])
    assert [bit.seen for bit in sent].count(1) == 1 and state.counted == 4
    assert word_of(sent[N - 1 :]) == wire.counter_telegram(5) & ~1


# -- silence, the generator and dropped telegrams ----------------------------------------------------------------


def test_a_silent_line_gets_a_counter_telegram_every_silence_plus_one_bits() -> None:
    """BK-30: S idle bit periods, then the generated telegram (driven), S - 12 idle, the next one, and so on."""
    _, sent = run([wire.IDLE_LEVEL] * (S + 4 * (S + 1)))
    period = [wire.IDLE_LEVEL] * (S - N + 1)
    gen = bits(GENERATED_TELEGRAM)
    assert [bit.out for bit in sent] == [wire.IDLE_LEVEL] * S + (gen + period) * 4
    assert [bit.drive for bit in sent] == [0] * S + ([1] * N + [0] * len(period)) * 4


def test_longest_idle_run_of_working_traffic_is_below_the_silence() -> None:
    """BK-30's evidence: back to back, no telegram holds the idle level longer than 12 bit periods."""
    words = [wire.data_telegram(b, c, k) for b, c, k in itertools.product(range(256), Cycle, (False, True))]
    longest = max(max(len(run) for run in format(w >> 1, "b").split("0")) for w in words)
    status = max(len(run) for c, k in itertools.product(Cycle, (False, True))
                 for run in format(wire.status_telegram(c, k) >> 1, "b").split("0"))  # fmt: skip
    assert max(longest, status) == N - 1 < S


@pytest.mark.parametrize("quiet", [S - 1, S])
def test_silence_closes_the_frame(quiet: int) -> None:
    """An ID check telegram after a data sequence is a check telegram unless the line was silent (S idle bit
    periods) in between."""
    opened, _ = run(bits(wire.data_telegram(0x12, Cycle.ID, False)))
    _, sent = run([1] * quiet + bits(wire.data_telegram(0x85, Cycle.ID, True)), opened)
    assert word_of(sent[quiet:]) == wire.data_telegram(0x85 + (quiet == S), Cycle.ID, True)


def test_every_collision_with_the_generator_drops_the_telegram() -> None:
    """A telegram beginning in each bit period of the generated one is received (its count kept) but sent as the
    driven idle level to its end; the idle count starts afresh with it."""
    for offset in range(1, N):
        line = [1] * (S + 1 + offset - 1) + bits(wire.counter_telegram(5)) + [1] * S
        state, sent = run(line)
        begin = S + offset
        assert word_of(sent[S : S + N]) == GENERATED_TELEGRAM
        dropped = sent[S + N : begin + N]
        assert all(bit.out == wire.IDLE_LEVEL and bit.drive for bit in dropped)
        assert sent[begin + N - 1].seen and state.counted == 5
        assert not any(bit.drive for bit in sent[begin + N :])  # S idle after it: the generator waits again
        assert state.quiet == S and state.drop == 0


def test_a_telegram_chained_to_a_dropped_one_is_dropped() -> None:
    status = bits(wire.status_telegram(Cycle.DATA, False), wire.STATUS_TELEGRAM_BITS)
    _, sent = run([1] * (S + 2) + bits(wire.counter_telegram(5) & ~(1 << (N - 1))) + status[1:] + [1])
    assert all(bit.out == wire.IDLE_LEVEL and bit.drive for bit in sent[S + N : -1])
    assert sent[-1] == CounterBit(wire.IDLE_LEVEL, 0, 0)


# -- chains of devices behind a break: the transaction level's count -----------------------------------------------


def bit_chain(devices: int, head: Sequence[int], periods: int) -> list[int]:
    """What arrives after ``devices`` blocks in a row whose first receives ``head`` then silence: each block sends
    bit period i on its input as bit period i + REPEATER_DELAY_BITS of its output (A10)."""
    line = list(head) + [wire.IDLE_LEVEL] * (periods - len(head))
    for _ in range(devices):
        _, sent = run(line)
        line = ([wire.IDLE_LEVEL] * wire.REPEATER_DELAY_BITS + [bit.out for bit in sent])[:periods]
    return line


def counts_at_bk(levels: Sequence[int], since: int = 0) -> list[int]:
    """The counts a BK's receiver keeps from a line, at each ``seen`` from bit period ``since`` on: a counter
    telegram's end (its count) or the line fallen silent (0, BK-58)."""
    state, counts = CounterState(), []
    for i, level in enumerate(levels):
        state, bit = counter_step(state, level)
        if bit.seen and i >= since:
            counts.append(state.counted)
    return counts


def traffic(devices: int, cut: int) -> list[int]:
    """The master's traffic on a working line (idle status telegrams, then an ID cycle) cut ``cut`` bit periods into
    the frame (negative: before it). The status telegrams before the frame last until it has passed ``devices``
    devices, whose lines begin silent (they start from reset): every device sees traffic when the break comes."""
    frame = wire.Frame.build(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + bytes([0x81, 0x05, 0xFF, 0x3F]))
    lead = -(-(wire.REPEATER_DELAY_BITS * devices + 2 * S + N) // wire.STATUS_TELEGRAM_BITS)
    levels = [*wire.status_levels(Cycle.DATA, False, lead), *wire.cycle_levels(frame, 2, True)]
    return [int(v) for v in levels[: lead * wire.STATUS_TELEGRAM_BITS + cut]]


PHANTOM_CUTS = range(1, wire.POS_CONTROL + 1)
"""Cuts inside the first telegram of a frame before its control bit: the idle level fills it to an ID check
telegram of byte FFh outside a frame, a counter telegram (BK-32)."""


def counts_behind(devices: int, cut: int) -> list[int]:
    """The counts a BK receives behind ``devices`` devices after a break ``cut`` bit periods into a frame (devices
    deeper than the silence generate once while the traffic has not reached them yet: not counted)."""
    head = traffic(devices, cut)
    return counts_at_bk(bit_chain(devices, head, len(head) + 3 * (S + 1) + 3 * devices), len(head))


@pytest.mark.parametrize("kind", [BranchKind.LBD_MR, BranchKind.LBD_OR])
def test_every_break_gives_the_transaction_levels_count(kind: BranchKind) -> None:
    """Behind every break of branches of 1 to 4 devices, cut anywhere in the master's traffic (mid-frame too), the
    BK receives only counter telegrams with exactly ``ring.lbd_count``'s count, from the first one on; a cut in the
    first header of a frame sends one saturated count (63, which locates nothing, BK-7) ahead of them."""
    for m in range(1, 5):
        for forward, back, behind in lbd_breaks(kind, m):
            expected = lbd_count(kind, m, forward, back)
            for cut in (-7, m % 3 + 1, 4, 80):
                counts = counts_behind(behind, cut)
                if cut in PHANTOM_CUTS:
                    assert counts[0] == wire.COUNTER_MAX
                    del counts[0]
                assert len(counts) >= 2 and set(counts) == {expected}, (m, forward, back, cut, counts)


@pytest.mark.parametrize("cut", [-7, *PHANTOM_CUTS, 4, 80])
def test_a_break_at_the_bks_own_input_reads_0(cut: int) -> None:
    """BK-58 (issue 12): a break right at the BK's return input (no device behind it, ``ring.lbd_count`` ``None``)
    leaves the BK's count 0 within a telegram and the silence after the break (13 + 33 bit periods), however the
    master's traffic was cut: a cut in a frame's first header still brings the saturated phantom of BK-32 (63)
    first, and the silence overwrites it; then only 0s, one every 33 bit periods."""
    head = traffic(0, cut)
    counts = counts_behind(0, cut)
    if cut in PHANTOM_CUTS:
        assert counts[0] == wire.COUNTER_MAX
        del counts[0]
    assert len(counts) >= 2 and set(counts) == {0}
    state = CounterState()
    for level in [*head, *[wire.IDLE_LEVEL] * (wire.DATA_TELEGRAM_BITS + S + 1)]:
        state, _ = counter_step(state, level)
    assert state.counted == 0 and lbd_count(BranchKind.LBD_OR, 1, set(), {0}) is None


@pytest.mark.parametrize("devices", [2, 8, 12])
def test_a_branch_silent_from_power_up_settles(devices: int) -> None:
    """Every line silent at once (before the master's first telegram): each device generates and drops its
    neighbour's telegram; then only the first device generates, and the BK's count is right after at most
    1 + devices // 4 counts of 1; before, the BK's own input falls silent between them (count 0, BK-58: first, and
    between the counts of 1 where a dropped telegram leaves a gap of more than 32 bit periods)."""
    counts = counts_at_bk(bit_chain(devices, [], 10 * (S + 1) + 3 * devices))
    wrong = counts.index(devices)
    assert counts[0] == 0 and set(counts[:wrong]) == {0, 1} and counts[:wrong].count(1) <= 1 + devices // 4
    assert set(counts[wrong:]) == {devices} and len(counts) - wrong >= 3


@pytest.mark.parametrize(("kind", "m"), [(BranchKind.LBD_OR, 63), (BranchKind.LBD_OR, 64), (BranchKind.LBD_MR, 32)])
def test_long_branches_saturate_as_the_transaction_level(kind: BranchKind, m: int) -> None:
    forward, back, behind = lbd_breaks(kind, m)[0]
    counts = counts_behind(behind, 40)
    assert len(counts) >= 2 and set(counts) == {lbd_count(kind, m, forward, back)}


# -- the clock timing and hostile inputs ---------------------------------------------------------------------------


def test_timing_constants() -> None:
    """The sent bit begins REPEATER_DELAY_BITS after it began on the pin (M8), like the chip's transmitter."""
    for fast in (0, 1):
        cpb = clocks_per_bit(fast)
        assert cpb == wire.clocks_per_bit((500_000, 2_000_000)[fast])
        begins = send_countdown(cpb) - cpb + 1  # clocks from the sample to the bit's first clock on the output
        assert cpb // 2 + begins + 2 == wire.REPEATER_DELAY_BITS * cpb  # the synchroniser's 2 stages
    assert OUTPUT_SLOTS == 6


@pytest.mark.parametrize(("call", "name"), [
    (lambda: counter_step(bad(None), 1), "state"),
    (lambda: counter_step(bad((13, 1, 0, 0, 0, 0, 0, 0, 13, 0)), 1), "state"),
    (lambda: counter_step(CounterState(bit=14), 1), "state.bit"),
    (lambda: counter_step(CounterState(quiet=S + 1), 1), "state.quiet"),
    (lambda: counter_step(CounterState(kind=bad(4)), 1), "state.kind"),
    (lambda: counter_step(CounterState(drop=bad(True)), 1), "state.drop"),
    (lambda: counter_step(CounterState(counted=bad(1.0)), 1), "state.counted"),
    (lambda: counter_step(CounterState(), 2), "level"),
    (lambda: counter_step(CounterState(), bad(True)), "level"),
    (lambda: counter_step(CounterState(), bad("1")), "level"),
    (lambda: clocks_per_bit(2), "fast"),
    (lambda: send_countdown(32), "cpb"),
    (lambda: sample_phase(bad(16.0)), "cpb"),
    (lambda: clocks_per_bit(bad(None)), "fast"),
    (lambda: wire.count_bit(13, 0, 1), "position"),
    (lambda: wire.count_bit(4, 2, 1), "level"),
    (lambda: wire.count_bit(4, 1, bad(True)), "carry"),
    (lambda: wire.counter_count(256), "byte"),
    (lambda: wire.counter_count(bad("x")), "byte"),
])  # fmt: skip
def test_hostile_inputs_are_named(call: object, name: str) -> None:
    assert callable(call)
    with pytest.raises(ArgumentError) as caught:
        call()
    assert caught.value.name == name
    assert str(caught.value).startswith(f"{name} must be")
