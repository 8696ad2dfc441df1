"""The reference RTL of the SUPI 3 OPC in Amaranth (the ``rtl`` extra), derived from the spec (``docs/rtl.md``):
the core (``core``), the serial µP interface (``upif``), the chip top (``chip``) and the strap tables (``tables``).
Import the submodules directly (``supi3.rtl.core``)."""
