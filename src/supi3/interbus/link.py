"""The device side of the INTERBUS data-link layer at transaction level: what a ring needs from a device.

A device is one segment of the distributed shift register (docs/interbus.md, "Ring"). At transaction level the
ring does the shifting, the per-line checks and the timing; a device only parallel-loads its register at the
start of a cycle and is told at the end whether the cycle was latched. This contract sits with the spec, below
both the devices that implement it (the SUPI 3 model, :class:`~supi3.interbus.device.PlainDevice`) and the rings
that call it (docs/architecture.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple, Protocol, runtime_checkable

from supi3.interbus.wire import Cycle


@runtime_checkable
class Device(Protocol):
    """What the ring needs from a device (docs/interbus.md, "Device protocol").

    Every call carries ``now``, the bus time in seconds, so a device can run its layer-2 watchdog
    (Table 3-13) without a clock of its own. Calls for one cycle come in this order: :meth:`load`, then
    :attr:`attention`, then exactly one of :meth:`latch` or :meth:`discard`.
    """

    @property
    def attention(self) -> bool:
        """The device has a new management flag (PF or WD) and wants the master to run an ID cycle.

        ORed into the CNTR word's ATTN flag as the check sequence passes (assumption A7).
        """
        ...

    def load(self, cycle: Cycle, now: float) -> bytes:
        """Parallel-load the shift register at the start of a cycle and return its contents in line order.

        ID cycle: the 16-bit ID register (``wire.word_bytes(wire.id_register(...))``). Data cycle: the IN data,
        ``wire.data_bytes(length_code)`` bytes, byte 0 (the most significant, manual 3.4.8) first. The length of
        the returned bytes is the register's length for this cycle.
        """
        ...

    def latch(self, cycle: Cycle, received: bytes, now: float) -> None:
        """The cycle passed every check and the master sent the latch telegrams: take over ``received``.

        ``received`` is what the register holds at the end of the data sequence: the OUT data in a data cycle,
        the command word (``wire.decode_command_word(wire.word_from_bytes(received))``) in an ID cycle.
        """
        ...

    def discard(self, cycle: Cycle, local_error: bool, now: float) -> None:
        """The cycle ended without a latch for this device ("invalid data cycle", Table 3-13).

        ``local_error`` is ``True`` when this device's own check of its incoming line failed; the device then
        sets the TE management bit of its ID register (assumption A8).
        """
        ...

    def reset(self, now: float) -> None:
        """The device detected an INTERBUS reset (reset pattern, or a silent line for ``IDLE_TIMEOUT_S``)."""
        ...

    def poll(self, now: float) -> None:
        """Bus time has advanced to ``now`` without a cycle reaching this device."""
        ...


class DataKernel(NamedTuple):
    """An optional fast path a device class offers the ring for a data cycle's consecutive devices of that class,
    as its class attribute ``data_kernel`` (docs/interbus.md, "Ring kernel").

    ``load(devices, now)`` must give what ``([d.load(Cycle.DATA, now) for d in devices], any(d.attention for d in
    devices))`` gives, and ``latch(devices, received, now)`` must do what ``d.latch(Cycle.DATA, r, now)`` does for
    each device ``d`` and its ``r``. The ring calls them only with a bus time ``now`` that is a finite ``float``
    >= 0, and ``received`` items that are ``bytes`` of the widths ``load`` returned; the kernel needs no argument
    checks of its own. tests/test_interbus_ring_kernel.py holds every kernel to the per-device path.
    """

    load: Callable[[Sequence[Any], float], tuple[list[bytes], bool]]
    latch: Callable[[Sequence[Any], Sequence[bytes], float], None]
