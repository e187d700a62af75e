"""Every kind of workbook the commands write, made once into one folder (issue 20): the
report-layer tests scan and print each of them."""
from pathlib import Path

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.studies.recorder import Recorder

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = ROOT / "templates" / "shot_a.xlsx"
LEGACY_IN = ROOT / "legacy_reference" / "shot_a_appendix_5us_input.xlsx"
LEGACY_OUT = ROOT / "legacy_reference" / "shot_a_appendix_5us_legacy.xlsx"


def _recording(folder, v0, rate, seed):
    p = airgun_xl.load(TEMPLATE).params.replace(delta=1e-6, v31=v0, v32=v0, v33=v0)
    rec = Recorder(rate=rate)
    trace = rec.record(airgun_xl.Shot(p).run(track=()), seed=seed)
    return rec.csv(trace, folder / f"measured_{v0:.0f}.csv")


def make_all(folder):
    """{name: path} of one workbook of each kind, written by the CLI into ``folder``."""
    folder = Path(folder)
    shot = folder / "shot.xlsx"
    shot.write_bytes(TEMPLATE.read_bytes())
    measured = _recording(folder, 243.53532, 50_000.0, 1)
    requirement = folder / "req.csv"
    requirement.write_text("frequency [Hz],srs [g]\n200,150\n1000,1500\n4000,6000\n")
    out = {name: folder / f"{name}.xlsx" for name in (
        "fill", "diff", "grid", "montecarlo", "sobol", "convergence", "srs", "design_srs",
        "compare", "calibrate_law", "calibrate_fit", "campaign", "history", "accept",
        "accept_corridor", "design_confidence")}
    day = folder / "day"
    day.mkdir()
    for name in ("shot_1", "shot_2"):
        (day / f"{name}.xlsx").write_bytes(TEMPLATE.read_bytes())
    commands = {
        "fill": ["fill", str(shot), "-o", str(out["fill"]), "--compare-models"],
        "legacy_fill": ["fill", str(LEGACY_IN), "-o", str(folder / "legacy_fill.xlsx")],
        "diff": ["diff", str(LEGACY_OUT), str(folder / "legacy_fill.xlsx"), "--report",
                 str(out["diff"])],
        "grid": ["sweep", str(shot), "--vary", "A28=150:250:5", "--vary", "E40=2.5e7:3e7:3",
                 "-o", str(out["grid"]), "--workers", "1"],
        "montecarlo": ["sweep", str(shot), "--mc", "64", "--sd", "E40=3%", "--sd",
                       "E43=10%", "--seed", "1", "-o", str(out["montecarlo"]),
                       "--workers", "1"],
        "sobol": ["sweep", str(shot), "--sobol", "16", "--sd", "E40=3%", "--sd", "A28=2%",
                  "--seed", "1", "-o", str(out["sobol"]), "--workers", "1"],
        "convergence": ["convergence", str(shot), "--levels", "5us,2us,1us", "-o",
                        str(out["convergence"])],
        "srs": ["srs", str(shot), "-o", str(out["srs"])],
        "design_srs": ["design", str(shot), "--target-srs", str(requirement), "-o",
                       str(out["design_srs"])],
        "compare": ["compare-measured", str(shot), str(measured), "--sign", "-1", "-o",
                    str(out["compare"])],
        "calibrate_law": ["calibrate", str(shot), str(measured), "--sign", "-1", "--cfc",
                          "600", "-o", str(out["calibrate_law"])],
        "calibrate_fit": ["calibrate", str(shot), str(measured), "--sign", "-1", "--fit",
                          "E40,E43", "-o", str(out["calibrate_fit"])],
        "campaign": ["fill", str(day), "--jobs", "1", "--summary", str(out["campaign"]),
                     "--archive", str(folder / "archive")],
        "history": ["history", "--archive", str(folder / "archive"), "-o", str(out["history"])],
        "accept": ["accept", str(shot), str(measured), "--sign", "-1", "--cfc", "1000",
                   "--peak", "9.5kG:15%", "--duration", "5ms:15%", "--velocity-change",
                   "240m/s:10%", "--srs", str(requirement), "--srs-tol", "-40dB,+40dB",
                   "-o", str(out["accept"])],
        "accept_corridor": ["accept", str(shot), str(measured), "--sign", "-1", "--cfc",
                            "1000", "--profile", "mil-std-810h-half-sine", "--peak", "9.5kG",
                            "--duration", "5ms", "--velocity-change", "240m/s", "-o",
                            str(out["accept_corridor"])],
        "design_confidence": ["design", str(shot), "--peak", "8.6kG:10%", "--duration",
                              "5.25ms:10%", "--velocity-change", "245m/s:10%", "--confidence",
                              "0.5", "--sd", "A28=1.5%", "--shots", "200", "-o",
                              str(out["design_confidence"])],
    }
    codes = {name: main(argv) for name, argv in commands.items()}
    return out, codes


#: The exit codes make_all's commands give: 0, but a shot that fails its specification (3).
EXPECTED_CODES = {"accept_corridor": 3}
