"""cocotb testbench modules that the verification kit runs inside the simulator process.

They are modules of the package, so they ship in the wheel and the simulator imports them by dotted name
(``supi3.verif.testbenches.lockstep_tb``) from wherever :mod:`supi3` itself is installed: no file path into a source
tree is needed. The project's own cocotb testbenches, which test the RTL and are not part of the kit, stay in
``sim/`` of the source tree.
"""
