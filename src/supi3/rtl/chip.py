"""The whole SUPI 3 chip in Amaranth: the INTERBUS core and the serial µP interface, pin for pin.

:class:`Supi3ChipRtl` matches the model ``supi3.top.Supi3Chip`` on every output pin on every 32 MHz clock. It joins
:class:`~supi3.rtl.core.Supi3Core` (built with its register-file ports) and :class:`~supi3.rtl.upif.UpifBlock`
(the µP interface and its register file) the way the model joins ``model.pins.Supi3Pins`` and
``spi.slave_pins.SlavePins`` through one ``model.registers.RegisterFile``:

* the core decodes the straps; in Init-µP modes it takes the ID register (bits 12..0), the data length, the IN
  bytes and the processor alarm from the block and strobes the block's core inputs at the clock edges at which the
  model's core calls the register file; at one edge the core's inputs act before the µP pins, as in the model;
* the block's µP pins are MFP[7..0] with the map of the pin declaration (:data:`supi3.pinout.UP_INPUTS`,
  :data:`~supi3.pinout.UP_OUTPUTS`); MFP[15..8] stay with the core;
* the block is held in reset while the core's power-up reset runs (``resu_drive``, or a power failure seen at this
  edge) and in every mode other than Init-µP, where MFP[7..0] are the core's.
"""

from __future__ import annotations

from amaranth.back import rtlil as amaranth_rtlil
from amaranth.back import verilog as amaranth_verilog
from amaranth.hdl import Const, Module, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from supi3.config import Variant
from supi3.errors import ArgumentError
from supi3.pinlevel import OE_SUFFIX
from supi3.pinout import (
    CORE_INPUTS,
    CORE_OUTPUTS,
    OPTICAL_LINE_INPUTS,
    STRAP_PINS,
    UP_INPUTS,
    UP_OUTPUTS,
    UP_PINS,
    up_input_port,
)
from supi3.rtl.core import REGISTER_FILE_INPUTS, REGISTER_FILE_OUTPUTS, Supi3Core
from supi3.rtl.tables import check_variant
from supi3.rtl.upif import UpifBlock

__all__ = ["Supi3ChipRtl", "rtlil", "verilog"]


class Supi3ChipRtl(wiring.Component):
    """The SUPI 3 chip with the pins of the model ``supi3.top.Supi3Chip`` (:mod:`supi3.pinout`), the strap ports of
    :class:`~supi3.rtl.core.Supi3Core` and its optical block's line side (:data:`~supi3.pinout.OPTICAL_LINE_INPUTS`).

    Parameters
    ----------
    variant:
        ``"opc"`` or ``"ls"`` (see :class:`~supi3.rtl.core.Supi3Core`).
    """

    def __init__(self, variant: Variant | str = Variant.OPC) -> None:
        try:
            self.variant = check_variant(variant)
        except ArgumentError:
            self._MustUse__silence = True  # rejected, never elaborated: no "created but never used" warning
            raise
        inputs = (*CORE_INPUTS, *STRAP_PINS, *OPTICAL_LINE_INPUTS)
        members: dict[str, object] = {pin.name: In(pin.width) for pin in inputs}
        members.update({pin.name: Out(pin.width) for pin in CORE_OUTPUTS})
        super().__init__(members)

    def elaborate(self, _platform: object) -> Module:
        m = Module()
        m.submodules.core = core = Supi3Core(self.variant, register_file=True)
        m.submodules.upif = upif = UpifBlock()
        for pin in (*CORE_INPUTS, *STRAP_PINS, *OPTICAL_LINE_INPUTS):
            m.d.comb += getattr(core, pin.name).eq(getattr(self, pin.name))
        for pin in CORE_OUTPUTS:
            m.d.comb += getattr(self, pin.name).eq(getattr(core, pin.name))
        for pin in REGISTER_FILE_OUTPUTS:
            m.d.comb += getattr(upif, pin.name).eq(getattr(core, pin.name))
        for pin in REGISTER_FILE_INPUTS:
            m.d.comb += getattr(core, pin.name).eq(getattr(upif, pin.name))
        for name, bit in UP_INPUTS.items():
            m.d.comb += getattr(upif, up_input_port(name)).eq(self.mfp_in[bit])
        levels: Value = Const(0, len(self.mfp_out))
        enables: Value = Const(0, len(self.mfp_oe))
        for name, bit in UP_OUTPUTS.items():
            enable = getattr(upif, name + OE_SUFFIX)
            levels |= (getattr(upif, name) & enable) << bit
            enables |= enable << bit
        with m.If(core.init_up):
            m.d.comb += [
                self.mfp_out.eq((core.mfp_out & ~UP_PINS) | levels),
                self.mfp_oe.eq((core.mfp_oe & ~UP_PINS) | enables),
            ]
        return m


def verilog(variant: Variant | str = Variant.OPC) -> str:
    """The Verilog of :class:`Supi3ChipRtl` for ``variant``, top module ``supi3_chip`` (for Verilator)."""
    text: str = amaranth_verilog.convert(Supi3ChipRtl(variant), name="supi3_chip", emit_src=False)
    return text


def rtlil(variant: Variant | str = Variant.OPC) -> str:
    """The RTLIL of :class:`Supi3ChipRtl` for ``variant``, top module ``supi3_chip`` (for yosys synthesis)."""
    text: str = amaranth_rtlil.convert(Supi3ChipRtl(variant), name="supi3_chip", emit_src=False)
    return text
