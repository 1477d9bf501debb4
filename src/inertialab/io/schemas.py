"""The record kinds of the five specs, one :class:`~inertialab.io.schema.Schema` each.

| kind | spec | one row per |
|---|---|---|
| ``gyro_log`` | 001 §2.2 (also static IMU logs for ``allan``) | sample at a uniform rate |
| ``thermal_tumble`` | 000 §2.3 | position visit at a chamber set point |
| ``triaxial_static`` | 002 §2.3 static-record CSV | static position |
| ``triaxial_raw`` | 002 §2.3 raw-log CSV | raw sample |
| ``dual_tumble`` | 003 §2.2 | DMM sample |
| ``storage_drift`` | 004 §2.1 | test of one unit on one day |
| ``clock_log`` | NIST SP 1065 §3 phase and frequency data | phase or frequency sample of a clock |

Analysis-specific checks (24 positions per set point, phases of a vibration run ...)
belong to the workflow that needs them (its checks before computing are
:mod:`inertialab.workflows.preflight`), not here.
"""

from __future__ import annotations

from inertialab.io.schema import Column as C
from inertialab.io.schema import Schema

ACC = ("acceleration",)
ACC_OR_COUNTS = ("acceleration", "counts")
RATE_OR_COUNTS = ("angular_rate", "counts")

GYRO_LOG = Schema(
    kind="gyro_log",
    source="spec 001",
    description="Continuous gyro or IMU log at a uniform rate.",
    columns=(
        C("t_s", description="time since record start, s (or give the sample rate)"),
        C("rate", dimensions=("angular_rate",), description="gyro rate output (e.g. rate_dph)"),
        C("dtheta", dimensions=("angle",), description="angle increment per sample (e.g. dtheta_arcsec)"),
        C("theta", dimensions=("angle",), description="cumulative angle (phase-like), for angle input"),
        C("accel", dimensions=ACC, description="accelerometer output (e.g. accel_mps2)"),
        C("gx", dimensions=("angular_rate",)), C("gy", dimensions=("angular_rate",)),
        C("gz", dimensions=("angular_rate",)),
        C("ax", dimensions=ACC), C("ay", dimensions=ACC), C("az", dimensions=ACC),
        C("vib_on", kind="int", description="1 while the shaker drives, else 0"),
        C("vib_freq_hz", description="instantaneous drive frequency, Hz, 0 when off"),
        C("vib_acc_g", description="commanded acceleration amplitude, g peak"),
        C("phase", kind="int", description="1, 2, 3 (P1/P2/P3)"),
        C("temp_c", description="case temperature, deg C"),
    ),
    one_of=(("rate", "dtheta", "theta", "accel", "gx", "gy", "gz", "ax", "ay", "az"),),
    time_column="t_s",
    time_order="strict",
    min_rows=2,
)

THERMAL_TUMBLE = Schema(
    kind="thermal_tumble",
    source="spec 000",
    description="Multi-position tumble at many chamber temperatures (one row per visit).",
    columns=(
        C("unit_id", kind="str"), C("lot_id", kind="str"), C("run_id", kind="str"),
        C("seq", kind="int", description="visit order within the run"),
        C("t_s", description="time since run start, s"),
        C("temp_set_c", required=True, description="chamber set point, deg C"),
        C("temp_meas_c", required=True, description="mean internal-sensor temperature, deg C"),
        C("temp_std_c", description="std of the temperature samples, deg C"),
        C("pos_index", kind="int", required=True, description="0..23"),
        C("angle_deg", description="nominal dividing-head angle = 15*pos_index, deg"),
        C("a_in_g", description="nominal sin(angle), g"),
        C("a_pend_g", description="nominal cos(angle), g"),
        C("output_mv", required=True, description="mean output over the window, mV"),
        C("output_std_mv", description="std of the output samples, mV"),
        C("n_samples", kind="int"),
        C("ramp_dir", kind="str", description="'up' / 'down'"),
        C("true_a_in_g"), C("true_temp_c"), C("true_output_mv"),
    ),
    time_column="seq",
    time_order="sort",
    sort_by=("seq", "t_s"),
    min_rows=24,
)

TRIAXIAL_STATIC = Schema(
    kind="triaxial_static",
    source="spec 002 static-record CSV",
    description="One row per static position of a triaxial accelerometer.",
    columns=(
        C("unit_id", kind="str"),
        C("pos_id", kind="int", required=True),
        C("ax", dimensions=ACC_OR_COUNTS, required=True),
        C("ay", dimensions=ACC_OR_COUNTS, required=True),
        C("az", dimensions=ACC_OR_COUNTS, required=True),
        C("n", kind="int"),
        C("ax_sd", dimensions=ACC_OR_COUNTS), C("ay_sd", dimensions=ACC_OR_COUNTS),
        C("az_sd", dimensions=ACC_OR_COUNTS),
        C("ref_x"), C("ref_y"), C("ref_z"),
        C("pitch_deg"), C("heading_deg"),
        C("face", kind="str", description="+x,-x,+y,-y,+z,-z"),
        C("temp_c"), C("t_start_s"), C("t_end_s"),
    ),
    min_rows=1,
)

TRIAXIAL_RAW = Schema(
    kind="triaxial_raw",
    source="spec 002 raw-log CSV",
    description="Continuous raw log of a triaxial IMU turned through static poses.",
    columns=(
        C("t_s", required=True),
        C("ax", dimensions=ACC_OR_COUNTS, required=True),
        C("ay", dimensions=ACC_OR_COUNTS, required=True),
        C("az", dimensions=ACC_OR_COUNTS, required=True),
        C("gx", dimensions=RATE_OR_COUNTS), C("gy", dimensions=RATE_OR_COUNTS),
        C("gz", dimensions=RATE_OR_COUNTS),
        C("temp_c"),
    ),
    time_column="t_s",
    time_order="strict",
    min_rows=10,
)

DUAL_TUMBLE = Schema(
    kind="dual_tumble",
    source="spec 003",
    description="Two orthogonal accelerometers on a dividing head, one row per DMM sample.",
    columns=(
        C("run_id", kind="str"),
        C("direction", kind="str", required=True, description="CCW / CW"),
        C("pos_index", kind="int", required=True, description="0..20 (20 = closure at 360 deg)"),
        C("theta_cmd_deg", required=True),
        C("theta_read_deg"),
        C("sample_index", kind="int"),
        C("t_s", required=True),
        C("v_a_v", required=True), C("v_b_v", required=True),
        C("t_a_c"), C("t_b_c"), C("t_r_c"),
        C("dmm_range_v"), C("nplc"),
    ),
    min_rows=7,
)

STORAGE_DRIFT = Schema(
    kind="storage_drift",
    source="spec 004",
    description="Long-term storage tests, one row per test of one unit.",
    columns=(
        C("unit_id", kind="str", required=True),
        C("date", kind="datetime"), C("timestamp", kind="datetime"),
        C("day", kind="int"),
        C("bias", dimensions=("acceleration", "current")),
        C("sf", dimensions=("current_per_acceleration", "voltage_per_acceleration", "ratio")),
        C("temp_c"), C("storage_temp_c"), C("humidity_pct"),
        C("test_method", kind="str"), C("station_id", kind="str"), C("operator", kind="str"),
        C("warmup_s", aliases=()), C("valid", kind="bool"), C("notes", kind="str", finite=False),
        C("true_bias", dimensions=("acceleration", "current")),
        C("true_sf", dimensions=("current_per_acceleration", "voltage_per_acceleration", "ratio")),
    ),
    one_of=(("date", "timestamp", "day"), ("bias", "sf")),
    time_order="sort",
    sort_by=("unit_id", "timestamp", "date", "day"),
    min_rows=2,
)

CLOCK_LOG = Schema(
    kind="clock_log",
    source="NIST SP 1065 §3 phase and frequency data",
    description=("Clock or oscillator record at a uniform rate: phase (time error, s ms us "
                 "ns ps) or fractional frequency (1 pct ppm ppb ppt, or Hz with a nominal "
                 "frequency), in any column the reader is told to use; the unit comes from "
                 "the unit option, else the column suffix (phase_ns, freq_hz). Empty cells "
                 "are missing samples (gaps), time stamps that skip whole intervals too."),
    columns=(
        C("t_s", description="time stamp, s (or give the sample rate or sidecar fs_hz); "
                             "skipped intervals are gaps, off-grid stamps an error"),
        C("phase", finite=False, description="phase / time error (also x, tie, time_error; "
                                             "phase_ns ...), empty = missing"),
        C("freq", finite=False, description="fractional frequency (also frequency, y; "
                                            "freq_ppb, freq_hz ...), empty = missing"),
    ),
    time_column="t_s",
    time_order="strict",
    min_rows=3,
    keep_unknown=True,
)

SCHEMAS: dict[str, Schema] = {
    s.kind: s for s in (GYRO_LOG, THERMAL_TUMBLE, TRIAXIAL_STATIC, TRIAXIAL_RAW,
                        DUAL_TUMBLE, STORAGE_DRIFT, CLOCK_LOG)
}


def flexible_bases() -> frozenset[str]:
    """Base names of every unit-flexible column (``rate``, ``gx``, ``ax`` ...), lower-case."""
    return frozenset(c.name for s in SCHEMAS.values() for c in s.columns if c.flexible)
