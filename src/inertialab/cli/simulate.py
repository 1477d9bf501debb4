"""``inertialab simulate KIND``: write a record from the virtual lab, one rig per study.

Each command runs its rig (:mod:`inertialab.sim`) with the settings of its
:mod:`inertialab.workflows.simulate` ``Config`` and hands the output to the workflow's
function of the same name, through the runner (``--out FILE``, ``--json``, ``--quiet``).
"""

from pathlib import Path

import typer

from inertialab.cli.runner import config_command
from inertialab.errors import InputError
from inertialab.workflows import simulate as ws
from inertialab.workflows import thermal_imu as wi

_OUT_HELP = ("Record file (.csv or .parquet); the sidecar .meta.json is written beside it "
             "(a regular file there is replaced; a directory, device or FIFO is refused).")


def _command(kind: str, config_cls, simulate):
    """The ``simulate KIND`` command: ``simulate(config, out) -> Written``."""

    @config_command(config_cls, out="file!", out_help=_OUT_HELP)
    def command(*, config, run):
        run.execute(f"simulate {kind}", lambda bar: simulate(config, Path(run.out)))

    command.__doc__ = simulate.__doc__
    return command


def _gyro_static(c, out):
    """A FOG at rest (the noise model of spec 001) with known Q N B K R."""
    from inertialab.sim.gyro_static import simulate

    return ws.gyro_static(simulate(c.preset, hours=c.hours, rate_hz=c.rate, seed=c.seed), c, out)


def _thermal_tumble(c, out):
    """Write a virtual thermal tumble record (23 set points x 24 positions, spec 000)."""
    from inertialab.sim.thermal_tumble import simulate

    return ws.thermal_tumble(simulate(c.preset, c.lot_seed, c.unit, seed=c.seed, ramp=c.ramp),
                             c, out)


def _thermal_imu(c, out):
    """A drone IMU temperature-ramp log (table) and its PX4 ULog <stem>.ulg."""
    from inertialab.sim import thermal_imu as si

    return wi.simulated(si.simulate(c.unit_seed, ramp=c.ramp, rate_hz=c.rate, seed=c.seed,
                                    n_instances=c.instances, faces=c.faces), si.ulog_bytes, c, out)


def _fog_vibration(c, out):
    """Simulate a FOG on a linear shaker (spec 001): three phases in the vibration record."""
    from inertialab.sim.fog_vibration import simulate

    return ws.fog_vibration(simulate(c.experiment, c.seed, c.preset, **c.overrides()), c, out)


def _triaxial_poses(c, out):
    """Write a virtual triaxial-poses record (raw logs also write <stem>.schedule.csv)."""
    from inertialab.sim.triaxial_poses import SCENARIOS, simulate, simulate_line

    if c.scenario not in SCENARIOS:
        raise InputError(f"unknown scenario '{c.scenario}' (known: {', '.join(SCENARIOS)})")
    rec = (simulate_line(c.n_units, seed=c.seed, g=c.g_local) if c.scenario == "line5000"
           else simulate(c.scenario, seed=c.seed, g=c.g_local))
    return ws.triaxial_poses(rec, c, out)


def _ferraris_session(c, out):
    """Write a virtual Ferraris session (six hand-placed faces, three turns; 102.4 Hz)."""
    from inertialab.sim.ferraris_session import simulate_ferraris

    return ws.ferraris_session(simulate_ferraris(
        seed=c.seed, placement_deg=c.placement_deg, angle_sigma_deg=c.angle_sigma_deg,
        counts=c.counts), c, out)


def _dual_tumble(c, out):
    """Write a virtual dual-tumble record (S5 writes <stem>_orient2 too)."""
    from inertialab.sim.dual import scenario_config, simulate_run, simulate_two_orientation

    cfg = scenario_config(c.scenario, draw_unit=c.draw_unit, **c.overrides())
    runs = (list(simulate_two_orientation(cfg, c.seed)) if cfg.scenario == "S5"
            else [simulate_run(cfg, c.seed)])
    return ws.dual_tumble(runs, cfg, c, out)


def _storage_drift(c, out):
    """Simulate a storage programme (spec 004) with ground-truth columns."""
    from inertialab.sim.drift import simulate_storage_batch

    return ws.storage_drift(simulate_storage_batch(
        c.units, c.days, c.preset, rng=c.seed, outliers=not c.no_outliers,
        missing_prob=c.missing_prob, skip_weekends=c.skip_weekends), c, out)


#: kind -> (settings, rig call); the order of ``simulate --help``.
RIGS = {
    "gyro-static": (ws.GyroStaticConfig, _gyro_static),
    "fog-vibration": (ws.FogVibrationConfig, _fog_vibration),
    "thermal-tumble": (ws.ThermalTumbleConfig, _thermal_tumble),
    "thermal-imu": (wi.ThermalImuSimConfig, _thermal_imu),
    "triaxial-poses": (ws.TriaxialPosesConfig, _triaxial_poses),
    "ferraris-session": (ws.FerrarisSessionConfig, _ferraris_session),
    "dual-tumble": (ws.DualTumbleConfig, _dual_tumble),
    "storage-drift": (ws.StorageDriftConfig, _storage_drift),
}


def register(app: typer.Typer, groups: dict) -> None:
    taken = {c.name for c in groups["simulate"].registered_commands}
    for kind, (config_cls, simulate) in RIGS.items():
        if kind not in taken:
            groups["simulate"].command(kind)(_command(kind, config_cls, simulate))
