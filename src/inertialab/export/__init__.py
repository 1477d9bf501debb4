"""The export floor: writers of the files other tools load directly, one registry of
them (:data:`EXPORTERS`), each entry declared once with its target tool. It sits above
the results it writes and takes them typed:

* kind ``noise``: a six-axis analysis, :class:`inertialab.noise.terms.imu_result.IMUNoise` or
  its values :class:`~inertialab.export.noise_params.NoiseValues`
  (:func:`export_noise`): ``kalibr`` (:mod:`.kalibr`), ``openvins`` (:mod:`.openvins`),
  ``vins`` and ``imu_utils`` (:mod:`.imu_utils`), ``gtsam`` (:mod:`.gtsam`), ``ros``
  (:mod:`.ros`);
* kind ``calibration``: a :class:`~inertialab.calib.triaxial.TriaxialCalibration`
  (:func:`export_calibration`): ``imucal`` (:mod:`.imucal`), ``imu_tk``
  (:mod:`.imu_tk`), ``kalibr`` (:mod:`.kalibr`, the scale-misalignment intrinsics);
* kind ``thermal``: a fuzzy :class:`~inertialab.calib.thermal.ThermalModel` (its ANFIS
  read through :meth:`inertialab.learn.anfis.ANFIS.rules`): ``c99`` (:mod:`.thermal_c`);
* kind ``thermal-imu``: a :class:`~inertialab.calib.thermal_imu.ThermalImuModel`:
  ``px4``, ``ardupilot`` (:mod:`.thermal_params`).

YAML is written through PyYAML's safe dumper (:func:`.yaml_text.dump_yaml`), never by
joining strings, so no value can add a key. Each format is tested by reading back with
the format's own reader or a parser of its documented grammar. The noise numbers are
continuous-time SI values (:mod:`.noise_params`). The command line offers every target
of this registry: ``allan --imu --export TARGET FILE`` and ``triaxial export --to
TARGET``. (This package was ``inertialab.io.exporters``, which still imports, with a
DeprecationWarning, for one release.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from inertialab.errors import InputError
from inertialab.export import (
    gtsam,
    imu_tk,
    imu_utils,
    imucal,
    kalibr,
    openvins,
    ros,
    thermal_c,
    thermal_params,
)
from inertialab.export import noise_params as _values  # the module (its function shares the name)
from inertialab.export.noise_params import (
    AxisValues,
    NoiseParams,
    NoiseValues,
    imu_utils_axes,
    per_axis,
    span_notes,
)
from inertialab.export.yaml_text import check_topic, yaml_number

if TYPE_CHECKING:
    from inertialab.calib.triaxial import TriaxialCalibration
    from inertialab.noise.terms.imu_result import IMUNoise

__all__ = ["EXPORTERS", "AxisValues", "Exporter", "NoiseParams", "NoiseValues", "check_topic",
           "export_calibration", "export_noise", "get", "noise_text", "targets", "yaml_number"]


@dataclass(frozen=True)
class Exporter:
    """One export target.

    Attributes
    ----------
    target : str      the name users give (``--export kalibr``, ``--to imu_tk``)
    kind : str        ``noise``, ``calibration`` or ``thermal``
    tool : str        the tool that reads the file, one line
    suffix : str      the usual file suffix
    text : callable   (kind ``noise``) ``text(NoiseParams, NoiseValues, options) -> str``
    write : callable  (other kinds) ``write(model, path, options) -> list of paths``

    Examples
    --------
    >>> e = get("noise", "kalibr")
    >>> e.tool, e.suffix
    ('Kalibr imu.yaml (kalibr_calibrate_imu_camera)', '.yaml')
    """

    target: str
    kind: str
    tool: str
    suffix: str
    text: Callable | None = None
    write: Callable | None = None


# ------------------------------------------------------------------ noise texts

def _kalibr(p, noise, o):
    return kalibr.noise_text(p, rostopic=o["rostopic"], note=(*span_notes(noise), *o["note"]))


def _openvins(p, noise, o):
    return openvins.noise_text(p, rostopic=o["rostopic"], note=(*span_notes(noise), *o["note"]))


def _vins(p, noise, o):
    return imu_utils.vins_text(p, g_norm=o["g_local"], imu_topic=o["rostopic"], note=(*span_notes(noise), *o["note"]))


def _imu_utils(p, noise, o):
    return imu_utils.imu_utils_text(p, name=o["name"], per_axis=imu_utils_axes(noise),
                                    note=(*span_notes(noise), *o["note"]))


def _gtsam(p, noise, o):
    return gtsam.gtsam_text(p, g=o["g_local"], note=(*span_notes(noise), *o["note"]))


def _ros(p, noise, o):
    return ros.ros_text(p, namespace=o["namespace"], per_axis=per_axis(noise),
                        note=(*span_notes(noise), *o["note"]))


# ------------------------------------------------------------ calibration writers

def _imucal(model, path, o):
    imucal.write_imucal(model, path, force=o.get("force", False))
    return [str(path)]


def _imu_tk(model, path, o):
    stem = str(path)[:-6] if str(path).endswith(".calib") else str(path)
    return imu_tk.write_imu_tk(model, stem, drop_g_sensitivity=o.get("drop_g_sensitivity", False),
                               force=o.get("force", False))


def _kalibr_intrinsics(model, path, o):
    kalibr.write_kalibr(model, path, force=o.get("force", False))
    return [str(path)]


#: Every export target, each declared once.
EXPORTERS: tuple[Exporter, ...] = (
    Exporter("kalibr", "noise", "Kalibr imu.yaml (kalibr_calibrate_imu_camera)", ".yaml",
             text=_kalibr),
    Exporter("openvins", "noise", "OpenVINS kalibr_imu_chain.yaml (with identity intrinsics)",
             ".yaml", text=_openvins),
    Exporter("vins", "noise", "VINS-Mono / VINS-Fusion config IMU block (acc_n gyr_n acc_w "
             "gyr_w)", ".yaml", text=_vins),
    Exporter("imu_utils", "noise", "imu_utils result file (avg-axis and per-axis)", ".yaml",
             text=_imu_utils),
    Exporter("gtsam", "noise", "GTSAM PreintegrationCombinedParams covariances", ".yaml",
             text=_gtsam),
    Exporter("ros", "noise", "ROS parameter file (rosparam load), per-axis values", ".yaml",
             text=_ros),
    Exporter("imucal", "calibration", "imucal calibration JSON (format 2.0.0, Ferraris)",
             ".json", write=_imucal),
    Exporter("imu_tk", "calibration", "imu_tk .calib text files, one per triad", ".calib",
             write=_imu_tk),
    Exporter("kalibr", "calibration", "Kalibr scale-misalignment IMU intrinsics", ".yaml",
             write=_kalibr_intrinsics),
    Exporter("c99", "thermal", "C99 .h/.c pair of a fuzzy thermal-compensation model",
             ".c", write=thermal_c.write_c),
    Exporter("px4", "thermal-imu", "QGroundControl .params with PX4's TC_* thermal "
             "compensation", ".params", write=thermal_params.write_px4),
    Exporter("ardupilot", "thermal-imu", "Mission Planner .param with ArduPilot's INS_TCALn_*",
             ".param", write=thermal_params.write_ardupilot),
)


def targets(kind: str) -> tuple[str, ...]:
    """The target names of ``kind``, registry order.

    Examples
    --------
    >>> targets("noise")
    ('kalibr', 'openvins', 'vins', 'imu_utils', 'gtsam', 'ros')
    >>> targets("thermal-imu")
    ('px4', 'ardupilot')
    """
    return tuple(e.target for e in EXPORTERS if e.kind == kind)


def get(kind: str, target: str) -> Exporter:
    """The entry of ``target`` (case-insensitive, ``-`` as ``_``); one-line error naming
    the choices when unknown.

    Examples
    --------
    >>> get("calibration", "IMU-TK").target
    'imu_tk'
    >>> get("noise", "rovio")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: argument 'export' must be one of kalibr, openvins, vins, imu_utils, gtsam, ros, got 'rovio'
    """
    t = str(target).strip().lower().replace("-", "_")
    for e in EXPORTERS:
        if e.kind == kind and e.target == t:
            return e
    arg = "export" if kind == "noise" else "to"
    raise InputError(f"argument '{arg}' must be one of {', '.join(targets(kind))}, got "
                     f"{str(target)[:40]!r}")


_NOISE_DEFAULTS = {"rostopic": "/imu0", "namespace": "imu", "name": "imu",
                   "g_local": 9.80665, "note": ()}


def noise_text(noise: IMUNoise | NoiseValues, target: str, **options) -> str:
    """The file text of the six-axis analysis ``noise`` for ``target`` (kind ``noise``).

    Options (all targets take them; each uses its own): ``rostopic`` (``/imu0``; Kalibr,
    OpenVINS, VINS), ``namespace`` (``imu``; ros), ``name`` (``imu``; imu_utils),
    ``g_local`` (9.80665 m/s^2; VINS ``g_norm``, GTSAM gravity), ``note`` (comment lines
    added to the file's head, e.g. an inflation applied to the values).

    Examples
    --------
    >>> values = NoiseValues(200.0, (AxisValues("gz", "gyro", 1e-4, 2e-6),
    ...                              AxisValues("az", "accel", 2e-3, 3e-4)))
    >>> text = noise_text(values, "kalibr", rostopic="/imu1")
    >>> for line in text.splitlines():
    ...     if not line.startswith("#"):
    ...         print(line)
    accelerometer_noise_density: 0.002
    accelerometer_random_walk: 0.0003
    gyroscope_noise_density: 0.0001
    gyroscope_random_walk: 2.0e-06
    rostopic: /imu1
    update_rate: 200.0
    """
    unknown = set(options) - set(_NOISE_DEFAULTS)
    if unknown:
        raise TypeError(f"unknown export options {sorted(unknown)}")
    o = {**_NOISE_DEFAULTS, **{k: v for k, v in options.items() if v is not None}}
    values = NoiseValues.of(noise)
    return get("noise", target).text(_values.noise_params(values), values, o)


def export_noise(noise: IMUNoise | NoiseValues, target: str, path, **options) -> list[str]:
    """Write :func:`noise_text` to ``path`` atomically; returns ``[path]``.

    Examples
    --------
    >>> import tempfile, yaml
    >>> from pathlib import Path
    >>> values = NoiseValues(100.0, (AxisValues("gx", "gyro", 2e-3, 3e-5),
    ...                              AxisValues("ax", "accel", 3e-3, 5e-4)))
    >>> path = Path(tempfile.mkdtemp()) / "imu.yaml"
    >>> [str(path)] == export_noise(values, "ros", path, namespace="imu0")
    True
    >>> yaml.safe_load(path.read_text())["imu0"]["per_axis"]["gx"]
    {'noise_density': 0.002, 'random_walk': 3e-05, 'random_walk_bound': False}
    """
    from inertialab.io.writers import atomic_write_text

    text = noise_text(noise, target, **options)
    atomic_write_text(path, text)
    return [str(path)]


def export_calibration(model: TriaxialCalibration, target: str, path, *, force: bool = False,
                       drop_g_sensitivity: bool = False) -> list[str]:
    """Write triaxial calibration ``model`` for ``target`` (kind ``calibration``); returns
    the paths written (imu_tk: ``<stem>_acc.calib`` and ``<stem>_gyro.calib``).

    Examples
    --------
    >>> import json, tempfile
    >>> import numpy as np
    >>> from pathlib import Path
    >>> from inertialab.calib import TriaxialCalibration
    >>> gyro = {"correction_matrix": np.eye(3), "offset": np.zeros(3), "raw_unit": "dps"}
    >>> cal = TriaxialCalibration("demo", "norm", {}, np.diag([1.01, 0.99, 1.0]),
    ...                           np.array([0.1, 0.0, -0.2]), "mps2", 9.81, gyro=gyro)
    >>> out = Path(tempfile.mkdtemp())
    >>> [Path(p).name for p in export_calibration(cal, "imu_tk", out / "unit7")]
    ['unit7_acc.calib', 'unit7_gyro.calib']
    >>> json.loads(Path(export_calibration(cal, "imucal", out / "c.json")[0]).read_text())["b_a"]
    [0.1, 0.0, -0.2]
    """
    return get("calibration", target).write(model, path, {"force": force,
                                                          "drop_g_sensitivity":
                                                          drop_g_sensitivity})
