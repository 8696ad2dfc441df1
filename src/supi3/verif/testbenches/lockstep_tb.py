"""cocotb testbench of the per-cycle lockstep path: runs the :class:`supi3.verif.lockstep.Job` named by the
``SUPI3_LOCKSTEP_JOB`` environment variable and pickles its outcome next to it. Started by
:meth:`supi3.verif.lockstep.Lockstep.run`, not by hand."""

from __future__ import annotations

import os
import pickle
from pathlib import Path
from typing import Any

import cocotb

from supi3.pinlevel import PinSpecError
from supi3.verif.cocotb_lockstep import lockstep
from supi3.verif.lockstep import JOB_ENV, Job
from supi3.verif.report import Outcome


@cocotb.test()
async def lockstep_job(dut: Any) -> None:
    """Step the job's model and the DUT together and record the outcome."""
    job: Job = pickle.loads(Path(os.environ[JOB_ENV]).read_bytes())
    try:
        outcome = await lockstep(
            dut, job.model_factory(), job.stimulus, reset_cycles=job.reset_cycles, window=job.window
        )
    except PinSpecError as error:  # handed to the caller's process, which raises it
        outcome = Outcome(0, 0.0, error=error)
    job.result.write_bytes(pickle.dumps(outcome))
