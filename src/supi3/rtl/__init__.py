"""The reference RTL of the SUPI 3 OPC in Amaranth (the ``rtl`` extra), derived from the spec (``docs/rtl.md``):
the core (``core``), the serial µP interface (``upif``), the chip top (``chip``), the strap tables (``tables``),
and the model adapters for lockstep runs (``harness``). Import the submodules directly (``supi3.rtl.core``)."""
