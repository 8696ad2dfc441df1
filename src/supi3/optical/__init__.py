"""Optical regulation of the SUPI 3 OPC (manual 1.6, 2.1.1, 2.1.2, 3.4.12, 3.4.13; OPC only, the LS has none).

The package spans layers like :mod:`supi3.spi` (docs/architecture.md): :mod:`supi3.optical.length` and
:mod:`supi3.optical.regulation` are spec (the manual's rules as data and pure functions; the decisions OPT-1 to
OPT-n of ``docs/assumptions/optical.md``); the fibre-link physics and the chip's optical block are model; the ring
of fibre-linked devices is a user of the model.
"""
