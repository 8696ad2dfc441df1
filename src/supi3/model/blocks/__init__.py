"""The blocks of the SUPI 3 chip core at pin level, composed by :class:`supi3.model.pins.Supi3Pins`.

One module per block, named as the blocks of the RTL core (:mod:`supi3.rtl.core`), so that a block's model and its
RTL can be read side by side (``docs/model.md``, "Blocks"):

===============  =================================  ======================================================
module           class                              block
===============  =================================  ======================================================
``receiver``     :class:`.receiver.Receiver`        synchroniser and line receiver
``frame``        :class:`.frame.FrameEngine`        frame engine: telegram framing, CRC and check sequence
``datapath``     :class:`.datapath.DataPath`        data path: shift register, load and latch
``transmitter``  :class:`.transmitter.Transmitter`  transmitter and repeater (DO2, DI1)
``outputs``      :class:`.outputs.Outputs`          outputs and diagnostics
``serial_io``    :class:`.serial_io.SerialIo`       serial I/O (SPI master mode, 3.3)
===============  =================================  ======================================================

Import the submodules directly (``supi3.model.blocks.receiver``). The blocks share one clock and one
:class:`~supi3.model.chip.Supi3` (the bus behaviour); :class:`~supi3.model.pins.Supi3Pins` owns the power-up reset,
wires the blocks to each other and runs them, cycle by cycle (``step``) or event by event (``run``).
"""
