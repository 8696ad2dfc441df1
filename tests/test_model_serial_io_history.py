"""Serial I/O (SPI master mode, 3.3) and register expansion (3.5) over random histories at transaction level: any
sequence of data cycles, line faults, fault clears and INTERBUS resets. A corrupted or invalid cycle never reaches a
peripheral's output (3.4.14: data are taken over only at the latch); after a reset the outputs are 0 (SM-9, RX-5);
the master only ever reads values the peripherals were given."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from supi3.config import decode
from supi3.expansion import line_to_chain
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Master
from supi3.interbus.ring import BitFlip, CorruptLoopback, Fault, Ring, Truncate
from supi3.model.chip import Supi3
from supi3.peripherals.serial import SerialBus, ShiftIn, ShiftOut, SpiAdc, SpiDac
from supi3.peripherals.sre import Sre1
from supi3.regmap import ID, SET

ANALOG = decode("10011", "1000")
"""RB, SPI 16 IN/16 OUT (Table 2-6): an ADC and a DAC on one bus."""
DIGITAL = decode("10011", "1011")
"""RB, SPI 32 IN/32 OUT (Table 2-6): four 74HCT165 and four 74HCT594."""
UP = decode("10011", "1110")
"""RB, Init-µP (Table 2-6): SET with ExtReg = 1 puts an IBS SRE 1 of 3 bytes in the data path (3.4.11, 3.5)."""
GAP_S = 8 / 500_000
"""The gap register expansion needs after a latched data cycle (docs/assumptions/expansion.md RX-4)."""


def _faults(n: int) -> st.SearchStrategy[Fault]:
    segments = st.integers(1, n + 1)
    cycles = st.integers(1, 3)
    return st.one_of(
        st.builds(BitFlip, segments, st.integers(0, 13 * (2 * 8 + 6) - 1), cycles),
        st.builds(Truncate, segments, st.integers(0, 8), cycles),
        st.builds(CorruptLoopback, segments, st.integers(0, 0xFFFF).filter(lambda v: v != wire.LOOPBACK_WORD), cycles),
    )


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_peripherals_only_ever_hold_what_a_valid_cycle_latched(data: st.DataObject) -> None:
    adc, dac, shift_in, shift_out = SpiAdc(16), SpiDac(16), ShiftIn(4), ShiftOut(4)
    analog, digital = Supi3(ANALOG), Supi3(DIGITAL)
    analog.attach_serial(SerialBus(adc, dac))
    digital.attach_serial(SerialBus(shift_in, shift_out))
    expanded, sre = Supi3(UP), Sre1(3)
    assert expanded.registers is not None
    expanded.registers.cpu_write(SET.address, SET.encode(EXTREG=1, LENGTH_CODE=0b01011))  # 3 bytes, Table 3-11
    expanded.registers.cpu_write(ID.address, 0x01)
    expanded.attach_expansion(sre)
    ring = Ring([analog, PlainDevice(0x02, 0b01001), digital, expanded])
    master = Master(ring, locate=False)
    assert master.start().ok
    given_in: dict[int, set[int]] = {1: {0}, 3: {0}, 4: {0}}  # every IN value a peripheral was ever given
    latched = {1: 0, 3: 0, 4: 0}  # the OUT word of the last latched data cycle (0 after a reset)
    for _ in range(data.draw(st.integers(1, 12), label="steps")):
        step = data.draw(st.sampled_from(["data", "data", "data", "fault", "clear", "reset"]), label="step")
        if step == "fault":
            ring.inject(data.draw(_faults(len(ring.devices))))
        elif step == "clear":
            ring.clear_faults()
        elif step == "reset":
            ring.clear_faults()
            assert master.start().ok  # Alarm Stop: an INTERBUS reset in every device
            latched = {1: 0, 3: 0, 4: 0}
        else:
            words = {1: data.draw(st.integers(0, 0xFFFF)), 3: data.draw(st.integers(0, 2**32 - 1)),
                     4: data.draw(st.integers(0, 2**24 - 1))}
            adc.set_input(value := data.draw(st.integers(0, 0xFFFF)))
            given_in[1].add(value)
            shift_in.set_inputs(value32 := data.draw(st.integers(0, 2**32 - 1)))
            given_in[3].add(value32)
            sre.set_inputs((value24 := data.draw(st.integers(0, 2**24 - 1))).to_bytes(3, "big"))
            given_in[4].add(int.from_bytes(line_to_chain(value24.to_bytes(3, "big")), "big"))
            for position, word in words.items():
                master.set_outputs(position, word.to_bytes({1: 2, 3: 4, 4: 3}[position], "big"))
            ring.idle(GAP_S)
            result = master.data_cycle()
            if result.ok and result.cycle is wire.Cycle.DATA:
                latched = words
        # What the peripherals show is always the last latched word: a failed cycle changed nothing.
        assert dac.output == latched[1] and shift_out.outputs == latched[3]
        assert sre.outputs == line_to_chain(latched[4].to_bytes(3, "big"))
        for position in (1, 3, 4):
            assert int.from_bytes(master.inputs(position), "big") in given_in[position]
    assert expanded.events["EXPANSION_OVERRUN"] == 0
