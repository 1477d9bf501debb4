"""The reading options declared once (cli/options.py): every decorated command gets all
of them; a command that already declares --rate or --unit keeps its own and the value
reaches both the command and ``read``."""

from pathlib import Path

import typer
from typer.testing import CliRunner

from inertialab.cli.options import READING_PARAMS, JsonOpt, reading_options
from inertialab.io.mapping import ReadOptions


def _app():
    app = typer.Typer()
    seen = {}

    @app.command("plain")
    @reading_options
    def plain(file: Path = typer.Argument(...), as_json: JsonOpt = False,
              read: ReadOptions = None):
        seen["plain"] = (file, as_json, read)

    @app.command("own")
    @reading_options
    def own(file: Path = typer.Argument(...),
            rate: float = typer.Option(None, "--rate", help="own help"),
            unit: str = typer.Option(None, "--unit"), read: ReadOptions = None):
        seen["own"] = (rate, unit, read)

    return app, seen


def test_every_reading_option_reaches_read():
    app, seen = _app()
    res = CliRunner().invoke(app, [
        "plain", "f.csv", "--json", "--map", "gx_rps=col2", "--sep", ";", "--decimal", ",",
        "--skip-rows", "2", "--time-col", "Stamp", "--time-unit", "us", "--rate", "400",
        "--unit", "g,dps", "--topic", "/imu", "--instance", "1", "--dataset", "imu/gyro",
        "--join", "g.txt", "--resample", "200"])
    assert res.exit_code == 0, res.output
    file, as_json, read = seen["plain"]
    assert as_json is True and file == Path("f.csv")
    assert read.column_map.to_text() == "gx_rps=col2"
    assert (read.parse.sep, read.parse.decimal, read.parse.skip_rows) == (";", ",", 2)
    assert (read.time_column, read.time_unit, read.rate_hz, read.unit) == ("Stamp", "us", 400.0,
                                                                          "g,dps")
    assert (read.topic, read.instance, read.dataset) == ("/imu", 1, "imu/gyro")
    assert read.join == (Path("g.txt"),) and read.resample_hz == 200.0
    assert {p.name for p in READING_PARAMS} >= {"map_text", "time_col", "topic", "dataset"}


def test_a_command_keeps_its_own_rate_and_unit():
    app, seen = _app()
    res = CliRunner().invoke(app, ["own", "f.csv", "--rate", "100", "--unit", "dph",
                                   "--topic", "/x"])
    assert res.exit_code == 0, res.output
    rate, unit, read = seen["own"]
    assert (rate, unit) == (100.0, "dph")
    assert (read.rate_hz, read.unit, read.topic) == (100.0, "dph", "/x")
    help_text = CliRunner().invoke(app, ["own", "--help"]).output
    assert help_text.count("--rate") == 1 and "own help" in help_text
