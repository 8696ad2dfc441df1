"""The serial µP interface of the SUPI 3 OPC: protocol engine (``upif``), pin-level model (``slave_pins``,
``block_pins``), the software SPI master that drives it (``master``, base install only) and the manual's timing
figures redrawn from its traces (``figures``; SVG needs the ``docs`` extra)."""
