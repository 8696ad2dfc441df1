"""The serial µP interface of the SUPI 3 OPC: protocol engine (``upif``) and pin-level model (``slave_pins``)."""
