"""Firmware in the loop: the firmware's own Cortex-M binary on an emulated microcontroller against the chip model.

- :mod:`supi3.mcu.core`: a Cortex-M0/M3 on unicorn with the exception model, SysTick and NVIC done here.
- :mod:`supi3.mcu.stm32`: the STM32F10x peripherals a SUPI 3 firmware uses (RCC, GPIO, EXTI, SPI).
- :mod:`supi3.mcu.board`: the board that wires them to the transaction-level chip on the firmware bench.
- :mod:`supi3.mcu.build`: one command that builds a firmware with the SDK's C driver and board port (ziglang).
- :mod:`supi3.mcu.session`: one run on the default bench and its report (``supi3 firmware run``).

Needs the ``firmware`` extra (``unicorn``, ``pyelftools``, ``ziglang``). Guide: docs/firmware-in-the-loop.md.
"""
