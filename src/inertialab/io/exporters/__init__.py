"""Writers of the files other tools load directly, one registry of them
(:data:`EXPORTERS`), each entry declared once with its target tool:

* kind ``noise`` (IMU noise parameters of a six-axis analysis, :func:`export_noise`):
  ``kalibr`` (:mod:`.kalibr`), ``openvins`` (:mod:`.openvins`), ``vins`` and
  ``imu_utils`` (:mod:`.imu_utils`), ``gtsam`` (:mod:`.gtsam`), ``ros`` (:mod:`.ros`);
* kind ``calibration`` (a triaxial calibration, :func:`export_calibration`): ``imucal``
  (:mod:`.imucal`), ``imu_tk`` (:mod:`.imu_tk`), ``kalibr`` (:mod:`.kalibr`, the
  scale-misalignment intrinsics);
* kind ``thermal`` (a fuzzy thermal-compensation model): ``c99`` (:mod:`.thermal_c`);
* kind ``thermal-imu`` (a drone IMU thermal model): ``px4``, ``ardupilot`` (:mod:`.thermal_params`).

YAML is written through PyYAML's safe dumper (:func:`._common.dump_yaml`), never by
joining strings, so no value can add a key. Each format is tested by reading back with
the format's own reader or a parser of its documented grammar. The noise numbers are
continuous-time SI values (:mod:`._common`). The command line offers every target of
this registry: ``allan --imu --export TARGET FILE`` and ``triaxial export --to TARGET``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from inertialab.errors import InputError
from inertialab.io.exporters import (
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
from inertialab.io.exporters import noise as _noise
from inertialab.io.exporters._common import NoiseParams, check_topic, yaml_number

__all__ = ["EXPORTERS", "Exporter", "NoiseParams", "check_topic", "export_calibration",
           "export_noise", "get", "noise_text", "targets", "yaml_number"]


@dataclass(frozen=True)
class Exporter:
    """One export target.

    Attributes
    ----------
    target : str      the name users give (``--export kalibr``, ``--to imu_tk``)
    kind : str        ``noise``, ``calibration`` or ``thermal``
    tool : str        the tool that reads the file, one line
    suffix : str      the usual file suffix
    """

    target: str
    kind: str
    tool: str
    suffix: str
    text: Callable | None = None
    write: Callable | None = None


# ------------------------------------------------------------------ noise texts

def _kalibr(p, noise, o):
    return kalibr.noise_text(p, rostopic=o["rostopic"], note=(*_noise.span_notes(noise), *o["note"]))


def _openvins(p, noise, o):
    return openvins.noise_text(p, rostopic=o["rostopic"], note=(*_noise.span_notes(noise), *o["note"]))


def _vins(p, noise, o):
    return imu_utils.vins_text(p, g_norm=o["g_local"], imu_topic=o["rostopic"], note=(*_noise.span_notes(noise), *o["note"]))


def _imu_utils(p, noise, o):
    return imu_utils.imu_utils_text(p, name=o["name"], per_axis=_noise.imu_utils_axes(noise),
                                    note=(*_noise.span_notes(noise), *o["note"]))


def _gtsam(p, noise, o):
    return gtsam.gtsam_text(p, g=o["g_local"], note=(*_noise.span_notes(noise), *o["note"]))


def _ros(p, noise, o):
    return ros.ros_text(p, namespace=o["namespace"], per_axis=_noise.per_axis(noise),
                        note=(*_noise.span_notes(noise), *o["note"]))


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
    """The target names of ``kind``, registry order."""
    return tuple(e.target for e in EXPORTERS if e.kind == kind)


def get(kind: str, target: str) -> Exporter:
    """The entry of ``target`` (case-insensitive, ``-`` as ``_``); one-line error naming
    the choices when unknown."""
    t = str(target).strip().lower().replace("-", "_")
    for e in EXPORTERS:
        if e.kind == kind and e.target == t:
            return e
    arg = "export" if kind == "noise" else "to"
    raise InputError(f"argument '{arg}' must be one of {', '.join(targets(kind))}, got "
                     f"{str(target)[:40]!r}")


_NOISE_DEFAULTS = {"rostopic": "/imu0", "namespace": "imu", "name": "imu",
                   "g_local": 9.80665, "note": ()}


def noise_text(noise, target: str, **options) -> str:
    """The file text of the six-axis analysis ``noise`` for ``target`` (kind ``noise``).

    Options (all targets take them; each uses its own): ``rostopic`` (``/imu0``; Kalibr,
    OpenVINS, VINS), ``namespace`` (``imu``; ros), ``name`` (``imu``; imu_utils),
    ``g_local`` (9.80665 m/s^2; VINS ``g_norm``, GTSAM gravity), ``note`` (comment lines
    added to the file's head, e.g. an inflation applied to the values).
    """
    unknown = set(options) - set(_NOISE_DEFAULTS)
    if unknown:
        raise TypeError(f"unknown export options {sorted(unknown)}")
    o = {**_NOISE_DEFAULTS, **{k: v for k, v in options.items() if v is not None}}
    return get("noise", target).text(_noise.noise_params(noise), noise, o)


def export_noise(noise, target: str, path, **options) -> list[str]:
    """Write :func:`noise_text` to ``path`` atomically; returns ``[path]``."""
    from inertialab.io.writers import atomic_write_text

    text = noise_text(noise, target, **options)
    atomic_write_text(path, text)
    return [str(path)]


def export_calibration(model, target: str, path, *, force: bool = False,
                       drop_g_sensitivity: bool = False) -> list[str]:
    """Write triaxial calibration ``model`` for ``target`` (kind ``calibration``); returns
    the paths written (imu_tk: ``<stem>_acc.calib`` and ``<stem>_gyro.calib``)."""
    return get("calibration", target).write(model, path, {"force": force,
                                                          "drop_g_sensitivity":
                                                          drop_g_sensitivity})
