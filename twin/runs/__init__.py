"""Recorded runs: the one reader (CSV and Parquet), validation, repairs and findings.

    from twin.runs import read_run
    run = read_run("examples/runs/spindle_9000rpm_30min.csv")
    run.time_s, run.speed_rpm, run.ambient_C, run.T_C        # T_C: (n, 5) T1..T5 in °C
    run.coolant_C, run.disp_um                               # optional; disp (n, 3) x, y, z
    run.valid["T2_C"]                                        # False: exclude from metrics
    run.quality                                              # findings (JSON-ready dicts)
    step = run.at(np.arange(0, run.duration_s, 4.0))         # values at solver steps
    state = run.before(60.0 * np.arange(1, 30))              # causal: last sample by then

Hard errors raise `twin.errors.InputError` naming file, line and column.
"""

from twin.runs.quality import QualityConfig
from twin.runs.run import (
    RecordedRun,
    Samples,
    check_replayable,
    read_run,
    read_table,
    run_from_table,
    write_quality,
    write_run,
)
from twin.runs.schema import (
    ALL_COLUMNS,
    DISPLACEMENTS,
    OPTIONAL,
    REQUIRED,
    SENSOR_NAMES,
    TEMPERATURES,
)

__all__ = [
    "ALL_COLUMNS",
    "DISPLACEMENTS",
    "OPTIONAL",
    "REQUIRED",
    "SENSOR_NAMES",
    "TEMPERATURES",
    "QualityConfig",
    "RecordedRun",
    "Samples",
    "check_replayable",
    "read_run",
    "read_table",
    "run_from_table",
    "write_quality",
    "write_run",
]
