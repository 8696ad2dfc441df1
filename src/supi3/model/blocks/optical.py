"""The optical regulation block at pin level: a synchronous machine with the ports of
:data:`~supi3.optical.regulation.BLOCK_INPUTS` and :data:`~supi3.optical.regulation.BLOCK_OUTPUTS`.

Manual 1.6 (behaviour on a reset), 1.6.1 (initialization in at most 6 ms, the length timer), 1.6.2 (online
regulation, optical diagnostics), 1.6.3 (MAU warnings), Table 3-17 / Table 2-8 (FO1..FO3), 3.4.12/3.4.13 (reads 8 to
11). Every change of a transmitter is a pure transition of :mod:`supi3.optical.regulation` (the model restates none
of them); the RTL counterpart :mod:`supi3.rtl.optical` re-implements them in gates and is held to this block cycle
by cycle (``tests/test_verif_lockstep_optical.py``). Decisions: OPT-20 onward of ``docs/assumptions/optical.md``.

What happens at the clock edge ending a cycle, from that cycle's inputs (:mod:`supi3.pinlevel`), first match wins:

1. ``ib_reset`` high: every transmitter off (OPT-21), the length timer stops, the 6 ms counter stops.
2. The first cycle with ``ib_reset`` low after it was high (its falling edge): every interface starts
   (:func:`~supi3.optical.regulation.start` with ``mode`` and ``present``) and the 6 ms counter is loaded with
   :data:`~supi3.optical.regulation.INIT_TIME_LIMIT_CLOCKS`.
3. Otherwise, per interface: a response strobe (``resp_valid``) applies
   :func:`~supi3.optical.regulation.init_response`, then a test strobe (``test_valid``) the online test
   (:func:`~supi3.optical.regulation.apply_test`: regulation, or the diagnostics MAU warning, OPT-22); then, on the
   edge where the 6 ms counter runs out, :func:`~supi3.optical.regulation.init_timeout` for the interface that was
   initializing (:attr:`~supi3.optical.regulation.OpticalStatus.initializing` of the state before the edge, OPT-56).

After 3, when the interface that was initializing no longer is (regulated, fallen back or timed out), the 6 ms counter
is loaded again: each interface has its own budget, in :data:`~supi3.optical.regulation.INIT_ORDER` (OPT-56).

One length timer measures the outgoing interface or the branch (OPT-57), at every edge, ib_reset aside: a
``len_start`` of either clears and starts it for that path (the outgoing interface's when both start at one edge; a
start for one path while it runs for the other abandons that measurement); while it runs, every
:func:`~supi3.optical.regulation.length_timer_enable_every`-th edge after the start counts one (saturating at
:data:`LENGTH_COUNT_BITS` bits); the ``len_stop`` of the path it runs for stops it after that edge's count and, unless
the block is off, stores :func:`~supi3.optical.length.timer_code` of the count with that path's ``medium`` bit
(OPT-24); the other path's ``len_stop`` does nothing. A ``len_start`` in the same cycle as a ``len_stop`` restarts it.

Outputs during a cycle come from the state (``fo`` also from ``run``): ``optical`` is
:func:`~supi3.optical.regulation.registers` of the status, byte k = read 8 + k; ``optical_we`` bit k is set while
byte k differs from what the previous cycle showed (0 after reset, when every byte is 0); ``mau``, ``fo``
(:func:`~supi3.optical.regulation.fo_lit`) and ``hold`` (a transmitter is initializing) per interface, bit i =
:class:`~supi3.optical.regulation.Interface` i. A ``mode`` of 3 is off, a ``resp`` of 3 no response (OPT-23).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Final

from supi3.checks import check_inputs, check_int, fail
from supi3.optical.length import Medium, timer_code
from supi3.optical.regulation import (
    BLOCK_INPUTS,
    BLOCK_OUTPUTS,
    INIT_TIME_LIMIT_CLOCKS,
    Interface,
    OpticalMode,
    OpticalStatus,
    Phase,
    Response,
    Transmitter,
    apply_test,
    fo_lit,
    init_response,
    init_timeout,
    length_timer_enable_every,
    registers,
    start,
)
from supi3.pinlevel import EventLog, Pin
from supi3.regmap.core import BYTE_BITS
from supi3.tables import BIT_RATES

__all__ = ["LENGTH_COUNT_BITS", "MEASURED", "RESP_BITS", "OpticalBlock", "block_mode"]

LENGTH_COUNT_BITS: Final = 14
"""Width of a length timer: 20 km one way at 2 Mbit/s is 6,400 counts there and back (1.6.1, Table 1-5), inside 13
bits with room to spare; it saturates (OPT-24)."""
RESP_BITS: Final = 2
"""Bits of one interface's ``resp`` (a :class:`~supi3.optical.regulation.Response`)."""
MEASURED: Final[tuple[Interface, Interface]] = (Interface.OUT, Interface.BRANCH)
"""The paths with a length timer, in the order of :attr:`OpticalStatus.length` (3.4.12)."""

_WIDTHS: Final[dict[str, int]] = {pin.name: pin.width for pin in BLOCK_INPUTS}
_STROBES: Final = ("ib_reset", "resp_valid", "test_valid", "len_start", "len_stop")
"""Inputs that change the state at the edge (besides the counters)."""
_MODES: Final[dict[int, OpticalMode]] = {mode.value: mode for mode in OpticalMode}
_RESPONSES: Final[dict[int, Response]] = {response.value: response for response in Response}


def block_mode(value: int) -> OpticalMode:
    """The ``mode`` port's value as an :class:`OpticalMode`; the unused code 3 is off (OPT-23)."""
    return _MODES.get(value, OpticalMode.OFF)



def _quiet_arguments(n: object, values: object) -> int:
    """:meth:`OpticalBlock.quiet`'s arguments checked by name: ``n`` as an int, or the error."""
    count = check_int("n", n, 0, limit="clocks")
    inputs = check_inputs(values, _WIDTHS)
    for name in _STROBES[1:]:
        if inputs[name]:
            raise fail(name, "0 in quiet() (a strobe changes the state at its edge: step() it)", inputs[name])
    return count


class _Timer:
    """The length timer (OPT-57): running, the path it measures (index into :data:`MEASURED`), the clocks since the
    last count, the count."""

    __slots__ = ("count", "path", "prescale", "running")

    def __init__(self) -> None:
        self.running = False
        self.path = 0
        self.prescale = 0
        self.count = 0


class OpticalBlock:
    """The optical block as a pin model (:class:`supi3.pinlevel.PinModel`); see the module docstring.

    Attributes
    ----------
    status:
        The block's :class:`OpticalStatus` (the state of the cycle to come).
    countdown:
        Edges until the initialization budget runs out, 0 when it is not running.
    """

    inputs: Sequence[Pin] = BLOCK_INPUTS
    outputs: Sequence[Pin] = BLOCK_OUTPUTS

    def __init__(self, time_limit: int = INIT_TIME_LIMIT_CLOCKS) -> None:
        self.time_limit = check_int("time_limit", time_limit, 1, INIT_TIME_LIMIT_CLOCKS,
                                    "the 6 ms budget in clocks (OPT-5); shorter only to test the timeout quickly")
        self.log = EventLog()
        self.reset()

    def reset(self) -> None:
        """The state after the ``sync`` reset (power-up): every transmitter off, nothing measured, the timer idle."""
        self.status = OpticalStatus()
        self.countdown = 0
        self._in_reset = False
        self._timer = _Timer()
        self._outputs_of: OpticalStatus | None = None
        self._regs = self._shown = registers(self.status)
        self._optical = self._mau = self._hold = 0
        self._fo: tuple[int, ...] = (0, 0)
        self.cycle = 0
        self.log.clear()

    @property
    def hold(self) -> bool:
        """The protocol core is held: a transmitter is initializing (1.6)."""
        return any(tx.phase is Phase.INIT for tx in self.status.transmitters)

    def step(self, inputs: Mapping[str, int]) -> dict[str, int]:
        """One clock (see :mod:`supi3.pinlevel`): this cycle's outputs, then the edge ending it.

        Raises
        ------
        ArgumentError
            ``inputs`` does not name exactly the block's input pins, or a value is not an integer within its pin's
            width (nothing changes).
        """
        values = check_inputs(inputs, _WIDTHS)
        outputs = self.outputs_now(values["run"])
        self.edge(values)
        return outputs

    def outputs_now(self, run: int) -> dict[str, int]:
        """The outputs during the current cycle (they depend on the state and ``run``, the master in RUN)."""
        status = self.status
        if status is not self._outputs_of:  # recomputed only when the status changed
            txs = status.transmitters
            regs = registers(status)
            self._regs = regs
            self._optical = sum(byte << (BYTE_BITS * k) for k, byte in enumerate(regs))
            self._mau = sum(int(tx.mau) << i for i, tx in enumerate(txs))
            self._fo = tuple(sum(int(fo_lit(tx, run)) << i for i, tx in enumerate(txs)) for run in (False, True))
            self._hold = int(any(tx.phase is Phase.INIT for tx in txs))
            self._outputs_of = status
        regs = self._regs
        shown = self._shown
        return {
            "optical_we": 0 if regs is shown else sum(1 << k for k in range(len(regs)) if regs[k] != shown[k]),
            "optical": self._optical,
            "mau": self._mau,
            "fo": self._fo[run],
            "hold": self._hold,
        }

    def edge(self, values: Mapping[str, int]) -> None:
        """The clock edge ending the current cycle, with that cycle's inputs ``values`` (checked by the caller: every
        input pin, each within its width); :meth:`outputs_now` must have been called in the cycle (it keeps what the
        cycle showed for ``optical_we``)."""
        if self._in_reset or self.countdown or self._timer.running or any(values[name] for name in _STROBES):
            self._edge(values)
        self._shown = self._regs
        self.cycle += 1

    def quiet(self, n: int, values: Mapping[str, int]) -> None:
        """``n`` clocks (outputs and edges) with the inputs ``values`` held, which must have no strobe but possibly
        ``ib_reset``: the same state as ``n`` :meth:`step` calls, in one go once only the counters move (the 6 ms
        counter and the length timer; the event-driven pin level, :meth:`supi3.model.pins.Supi3Pins.run`).

        Raises
        ------
        ArgumentError
            ``n`` is not an integer >= 0, ``values`` not the block's inputs, or a strobe in ``values`` is set.
        """
        if (type(n) is not int or n < 0 or not isinstance(values, Mapping) or not values.keys() >= _WIDTHS.keys()
                or any(values[name] for name in _STROBES[1:])):  # fmt: skip
            n = _quiet_arguments(n, values)
        run = values["run"]
        while n > 0 and not (self._in_reset == bool(values["ib_reset"]) and not 0 < self.countdown <= n
                             and self._outputs_of is self.status and self._shown is self._regs):  # fmt: skip
            self.outputs_now(run)
            self.edge(values)
            n -= 1
        if n <= 0:
            return
        if not self._in_reset:  # no edge changes the status: the counters move by n (OPT-24, OPT-25)
            self.countdown = max(self.countdown - n, 0)
            timer = self._timer
            if timer.running:
                every = length_timer_enable_every(BIT_RATES[values["fast"]])
                ticks, timer.prescale = divmod(timer.prescale + n, every)
                timer.count = min(timer.count + ticks, (1 << LENGTH_COUNT_BITS) - 1)
        self.cycle += n

    def next_change(self, ib_reset: int) -> int | None:
        """Edges from the current cycle to the first that changes the status with ``ib_reset`` held and no strobe
        (the start after an INTERBUS reset, the 6 ms budget's end), or 0 when the current cycle shows a change to the
        register file (``optical_we``); ``None`` if none does (the event-driven pin level visits these cycles)."""
        if self._outputs_of is not self.status or self._in_reset != bool(ib_reset):
            return 0
        return self.countdown - 1 if self.countdown else None

    def _edge(self, v: Mapping[str, int]) -> None:
        """The clock edge ending the cycle with inputs ``v`` (the order of the module docstring)."""
        mode = block_mode(v["mode"])
        bit_rate = BIT_RATES[v["fast"]]
        status = self.status
        if v["ib_reset"]:
            if not self._in_reset:
                self.log.add(self.cycle, "INTERBUS reset: transmitters off")
            self._in_reset = True
            self.countdown = 0
            self._timer.running = False
            off = (Transmitter(), Transmitter(), Transmitter())
            if status.transmitters != off:
                self.status = OpticalStatus(off, status.length, status.medium)
            return
        current = status.initializing
        if self._in_reset:
            self._in_reset = False
            self.countdown = self.time_limit
            txs = tuple(start(mode, bool(v["present"] >> i & 1)) for i in Interface)
            self.log.add(self.cycle, "start in {}: {}", mode.name, [tx.phase.value for tx in txs])
        else:
            txs = status.transmitters
            if v["resp_valid"] or v["test_valid"]:
                txs = tuple(self._strobes(status[i], i, v) for i in Interface)
            if self.countdown:
                self.countdown -= 1
                if not self.countdown and current is not None:
                    txs = tuple(init_timeout(tx) if i is current else tx for i, tx in zip(Interface, txs, strict=True))
                    self.log.add(self.cycle, "{} 6 ms budget over", current.name)
        if txs != status.transmitters:
            status = OpticalStatus((txs[0], txs[1], txs[2]), status.length, status.medium)
            if current is not None and txs[current].phase is not Phase.INIT:  # the next one's own 6 ms (OPT-56)
                self.countdown = self.time_limit
        if v["len_start"] or v["len_stop"] or self._timer.running:
            status = self._lengths(status, v, mode, bit_rate)
        self.status = status

    def _strobes(self, tx: Transmitter, i: Interface, v: Mapping[str, int]) -> Transmitter:
        """Interface ``i``'s response, then its test, of this cycle."""
        if v["resp_valid"] >> i & 1:
            resp = v["resp"] >> (RESP_BITS * i) & ((1 << RESP_BITS) - 1)
            response = _RESPONSES.get(resp)
            if response is not None:
                tx = init_response(tx, response)
                self.log.add(self.cycle, "{} response {}: {}", i.name, response.name, tx)
        if v["test_valid"] >> i & 1:
            tx = apply_test(tx, bool(v["ack1"] >> i & 1), bool(v["ack2"] >> i & 1))
            self.log.add(self.cycle, "{} test: {}", i.name, tx)
        return tx

    def _lengths(self, status: OpticalStatus, v: Mapping[str, int], mode: OpticalMode, bit_rate: int) -> OpticalStatus:
        """The length timer's edge (see the module docstring)."""
        timer = self._timer
        if timer.running:
            timer.prescale += 1
            if timer.prescale == length_timer_enable_every(bit_rate):
                timer.prescale = 0
                timer.count = min(timer.count + 1, (1 << LENGTH_COUNT_BITS) - 1)
            i = MEASURED[timer.path]
            if v["len_stop"] >> i & 1:
                timer.running = False
                if mode is not OpticalMode.OFF:
                    medium = Medium(v["medium"] >> i & 1)
                    status = status.with_length(i, timer_code(timer.count, bit_rate, medium), medium)
                    self.log.add(self.cycle, "{} length: {} counts", i.name, timer.count)
        started = [k for k, i in enumerate(MEASURED) if v["len_start"] >> i & 1]
        if started:  # the first of MEASURED wins (OPT-57)
            timer.running, timer.path, timer.prescale, timer.count = True, started[0], 0, 0
        return status

    def recent_events(self) -> list[str]:
        """The block's last events, for mismatch reports."""
        return self.log.recent()
