"""Behavioural models of the SUPI 3 OPC's blocks. Import the submodules directly (``supi3.model.registers``)."""
