"""A simulated lab (issue 45): lots of honeycomb whose true crush law differs from the report's,
fired until PASS or 5 shots, once with `airgun-xl next` and once with the rule labs use by
hand; how soon each passes, and whether next's predicted P(PASS) came true.

    python benchmarks/bench_closed_loop.py [--lots N] [--draws N] [--vary CELL] [--gun] [--quick]
    python benchmarks/bench_closed_loop.py --call [--quick]

The lab, on shot A (the template):
- a lot's true law is the report's times a scale drawn with a 10 % spread, tilted with speed
  (a slope drawn with a 5 % spread per 240 m/s, through 240 m/s);
- the gun fires the set velocity with a 1.5 % scatter; zeta scatters 10 % a shot;
- the recorder: 51.2 kHz, a 4-pole anti-alias at a fifth of the rate, noise 1 % of the peak
  half white and half correlated (AR(1), 0.9), an offset of 20 g, 16 bits over +/- 30 kG;
- the client: peak 8.5 kG +/- 5 % and duration 5 ms +/- 20 %, the default record.

Every lot's first shot is the setting `design --confidence` finds on the nominal law (the
gun's, the lot-to-lot 10 % and zeta's scatter drawn, each prediction judged as a recording of
this recorder's noise would be). Then:
- **next**: `airgun_xl.next_shot` after each shot (the gun's 1.5 % and zeta's 10 % given as
  the scatter; with `--vary E13`, the mitigator's radius set with the velocity), the next
  shot fired from the workbook it wrote;
- **by hand**: the velocity scaled by (target / measured peak) ^ (1 / gamma), gamma the
  model's own d ln(peak) / d ln(v) on the nominal law at the velocity fired.
Both meet the same lots and the same draws of the gun, zeta and the recorder's noise. Beside
each shot fired from a proposal, `--replicates` more (3 by default: draws of their own) are
fired and judged, so that each band of predicted P(PASS) holds enough shots to be judged; they
do not enter the lot's chain. Each proposal's expected judged figures and the measured ones of
its shots are placed in their tolerances (the middle half: within half the half-width).

`--call` times one `airgun-xl next` as a whole process on a lot of 5 recorded shots (the
fifth, with the default 2,000 draws a setting; alone, with `--vary E13`, and with `--gun`
among 199 other lots of the gun, whose records it reads; and on a lot of 5 shots spread over
205 to 252 m/s, where the law is fitted whole and tested): its wall time (median of 5, after a
warm-up) and peak RSS, against the issue's 10 s and 1 GB.

It prints, for both, the share of lots passed by the first, second and third shot and the
mean shots to the first PASS (a lot not passed in 5 counts as 6), and, for next, the observed
pass rate in each band of predicted P(PASS) with its Wilson 95 % interval, and the Brier
score. Targets (issue 45, 200 lots): at least 90 % pass by the second shot with next, next at
least as good as by hand at every shot count, and every band of 30 or more shots honest (its
mean prediction inside the observed rate's interval).
"""
import argparse
import dataclasses
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import openpyxl
from bench_fill import TEMPLATE, machine

import airgun_xl
from airgun_xl.app.specifying import keyword_fields, resolve
from airgun_xl.crush_law import CRUSH_FIT_RANGE, LEGACY_LAW, crush_factor
from airgun_xl.errors import AirgunXlError
from airgun_xl.studies.acceptance import judge_record
from airgun_xl.studies.calibrate import _chebyshev_nodes, law_through
from airgun_xl.studies.closed_loop import brier, reliability
from airgun_xl.studies.recorder import Recorder

SPEC = {"peak": "8.5kG:5%", "duration": "5ms:20%"}
V_RANGE = (10.0, 260.0)  # [m/s] the gun's settings (design's search range for A28)
TARGET_KG = 8.5
MOST_SHOTS = 5
GUN, ZETA, LOT_SPREAD, TILT_SPREAD = 0.015, 0.10, 0.10, 0.05
RECORDER = Recorder(rate=51_200, noise=0.01, offset_g=20.0, pre_trigger=1.5e-3, sign=1.0,
                    colour=0.9, colour_share=0.5, full_scale=30.0, bits=16)


#: The harder lab's settings (main's options): the gun's mean offset [-], the spread of a
#: curvature of the law with speed the model's scale and tilt cannot take [-], the recorder.
LAB = {"bias": 0.0, "curvature": 0.0, "recorder": RECORDER}


def true_law(rng):
    """A lot's law: the report's, scaled and tilted with speed (and, with ``--curvature``,
    bent: a shape the update's scale and tilt cannot represent)."""
    scale = max(0.6, rng.normal(1.0, LOT_SPREAD))
    tilt = rng.normal(0.0, TILT_SPREAD)
    bend = rng.normal(0.0, LAB["curvature"]) if LAB["curvature"] else 0.0
    lo, hi = CRUSH_FIT_RANGE
    nodes = _chebyshev_nodes(lo, hi, 7)
    x = (nodes - 240.0) / 240.0
    values = crush_factor(nodes, LEGACY_LAW) * scale * (1 + tilt * x) * (1 + bend * x * x)
    return law_through(nodes, values, CRUSH_FIT_RANGE)


def with_velocity(path, v):
    """A copy of the template at ``path`` with A28 (and so A29, A30) set to ``v``."""
    book = openpyxl.load_workbook(TEMPLATE)
    book["Sheet1"]["A28"] = float(v)
    book.save(path)
    return path


def fire(workbook, law, draws, path):
    """The lab fires ``workbook`` on a lot of law ``law``; the recorder's CSV at ``path``."""
    p = airgun_xl.load(workbook).params
    v = p.v31 * (1 + LAB["bias"] + GUN * draws[0])
    q = p.replace(v31=v, v32=v, v33=v, zeta=p.zeta * (1 + ZETA * draws[1]), crush_law=law)
    trace = LAB["recorder"].record(airgun_xl.Shot(params=q).run(), seed=int(draws[2]))
    path.write_text("time [s],acceleration [kG]\n" + "".join(
        f"{t!r},{a!r}\n" for t, a in zip(trace.time.tolist(), trace.accel_kg.tolist(),
                                           strict=True)))
    return path


def judged_peak(v, noise):
    """The model's peak on the nominal law at ``v``, judged as a recording of ``noise``."""
    p = airgun_xl.load(TEMPLATE).params.replace(v31=v, v32=v, v33=v)
    run = airgun_xl.Shot(params=p).run()
    spec = resolve(airgun_xl.load(TEMPLATE), keyword_fields("bench", SPEC))
    ok = np.isfinite(run.accel_kg)
    verdict = judge_record(run.history.time[ok], run.accel_kg[ok], spec, "model", noise=noise,
                           prediction=True)
    return next(c.value for c in verdict.criteria if c.name == "peak")


def by_hand(lot, law, first, work, draws):
    """Shots to the first PASS (6: none in 5) by the rule labs use by hand."""
    v = first
    for k in range(MOST_SHOTS):
        shot = with_velocity(work / f"hand{k}.xlsx", v)
        rec = fire(shot, law, draws[k], work / f"hand{k}.csv")
        verdict = airgun_xl.accept(shot, rec, **SPEC)
        if verdict.passed:
            return k + 1
        noise = float(verdict.verdict.quality.base.noise)
        measured = next(c.value for c in verdict.criteria if c.name == "peak")
        gamma = math.log(judged_peak(v * 1.01, noise) / judged_peak(v / 1.01, noise)) / \
            math.log(1.01 ** 2)
        moved = v * (TARGET_KG / measured) ** (1 / gamma) if gamma > 0 else math.nan
        if not math.isfinite(moved):  # the rule has no answer: the lot is not passed
            return MOST_SHOTS + 1
        v = min(max(moved, V_RANGE[0]), V_RANGE[1])  # what the gun can be set to
    return MOST_SHOTS + 1


#: The lots next refused (lot, shot, the refusal): counted as never passed by next.
REFUSED: list[tuple[int, int, str]] = []


#: Where each tolerance's nominal and half-width sit: (nominal, half-width) in the verdict's
#: units (kG, ms), from SPEC.
TOLERANCES = {"peak": (8.5, 0.425), "duration": (5.0, 1.0)}

#: Per proposal fired: {"expected": {figure: position}, "measured": [{figure: position}]},
#: a position (value - nominal) / half-width (-1 and 1 the limits; the middle half within
#: 0.5).
CENTRES: list[dict] = []

#: Per shot fired from a proposal (``--dump``): the lot, the shot's place in it, whether a
#: replicate, the P(PASS) predicted, the verdict, the model error drawn (its words), and the
#: expected and measured positions in the tolerances.
SHOTS: list[dict] = []


def positions(figures):
    """{figure: (value - nominal) / half-width} of ``figures`` {name: value in kG or ms}."""
    return {k: (figures[k] - mid) / half for k, (mid, half) in TOLERANCES.items()
            if k in figures and math.isfinite(figures[k])}


def replicates(shot, law, lot, k, count, work):
    """``count`` more shots fired from the proposal ``shot`` (the lot's ``k``-th shot), each
    its own draw of the gun, zeta and the recorder's noise (a stream of its own, so the lot's
    own draws stay the by-hand rule's): [(passed, {figure: value})]."""
    rng = np.random.default_rng([1000 + lot, k, 77])
    out = []
    for r in range(count):
        draw = (rng.normal(), rng.normal(), int(rng.integers(1 << 30)))
        rec = fire(shot, law, draw, work / f"rep{k}_{r}.csv")
        verdict = airgun_xl.accept(shot, rec, **SPEC)
        out.append((verdict.passed, {c.name: c.value for c in verdict.criteria}))
    return out


def with_next(lot, law, first, work, draws, n_draws, calls, vary=None, gun=None,
              count=0):
    """Shots to the first PASS by next; each (predicted P(PASS), passed) of a proposal
    fired, and of ``count`` replicates fired from each proposal beside it. Every lot in one
    archive (``work``'s parent's), as a lab keeps one; with ``gun``, the gun's scatter
    pooled over them (``next --gun``); ``calls`` gets (seconds, the gun's words, the law's
    update)."""
    shot = with_velocity(work / "next0.xlsx", first)
    predicted, record, expected, error, proposal = None, [], {}, "", {}
    # one lab, one archive: the lots' pairs of expected and measured figures are the model
    # error's record (issue 60); with a per-lot archive every lot drew the prior
    archive = work.parent / "archive"
    for k in range(MOST_SHOTS):
        rec = fire(shot, law, draws[k], work / f"next{k}.csv")
        started = time.perf_counter()
        try:
            out = airgun_xl.next_shot(shot, rec, archive=archive, lot=f"LOT-{lot}",
                                      new_lot=k == 0, sd=[f"A28={GUN:.1%}", f"E43={ZETA:.0%}"],
                                      shots=n_draws, seed=lot * 10 + k,
                                      output=work / f"next{k + 1}.xlsx", vary=vary, gun=gun,
                                      **SPEC)
        except AirgunXlError as exc:  # next refuses the lot (a law the model cannot fit):
            REFUSED.append((lot, k + 1, str(exc)))  # the lab takes it by hand from here
            return MOST_SHOTS + 1, record
        calls.append((time.perf_counter() - started, out.gun, out.update))
        if predicted is not None:
            record.append((predicted, out.verdict.passed))
            fired = [(out.verdict.passed, {c.name: c.value for c in out.verdict.criteria}),
                     *replicates(shot, law, lot, k, count, work)]
            record += [(predicted, passed) for passed, _ in fired[1:]]
            CENTRES.append({"expected": expected,
                            "measured": [positions(f) for _, f in fired]})
            SHOTS.extend({"lot": lot, "shot": k + 1, "replicate": r > 0,
                          "predicted": predicted, "passed": passed, "model_error": error,
                          "expected": expected, "measured": positions(f), **proposal,
                          "values": f}
                         for r, (passed, f) in enumerate(fired))
        if out.verdict.passed:
            return k + 1, record
        predicted, shot, error = out.best.probability, out.output, out.model_error
        proposal = {"failures": dict(out.best.failures), "draws": out.best.shots,
                    "figures": {k: list(v) for k, v in out.best.figures.items()},
                    "model_figures": {k: list(v) for k, v in out.best.model_figures.items()}}
        expected = positions({name: v[1] * (1e3 if name == "duration" else 1.0)
                              for name, v in out.best.figures.items()})
    return MOST_SHOTS + 1, record


def first_setting(n_draws):
    """design --confidence on the nominal law, judged as this recorder's shots are (one rule
    for a prediction and a recording: the specification's record)."""
    from airgun_xl.studies.design import variable
    from airgun_xl.studies.first_shot import solve_confidence
    from airgun_xl.studies.model_error import ModelError
    from airgun_xl.studies.sweep import parse_sds

    shot = airgun_xl.load(TEMPLATE)
    spec = resolve(shot, keyword_fields("bench", SPEC))
    sds = parse_sds([f"A28={GUN:.1%}", f"E40={LOT_SPREAD:.0%}", f"E43={ZETA:.0%}"])
    found = solve_confidence(shot.params, spec, variable("A28"), sds, n_draws, 1,
                             model_error=ModelError.prior())
    return found.best.setting, found.best.probability


#: A child that runs ``next`` and prints its exit status and peak RSS [kB] (POSIX getrusage:
#: the benchmarks' machine, not the package's platforms); 3 (P(PASS) not reached) is a run.
NEXT_RSS = (
    "import resource, subprocess, sys\n"
    "code = subprocess.run(sys.argv[1:], capture_output=True).returncode\n"
    "print(code, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
)


def timed(cmd, times):
    """One warm-up, then ``times`` runs of ``cmd``: wall times [s] and peak RSS [MB]."""
    import subprocess

    walls, rss = [], []
    for k in range(times + 1):
        started = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", NEXT_RSS, *cmd], capture_output=True,
                              text=True, check=True)
        code, peak = done.stdout.split()
        if code not in ("0", "3"):
            raise SystemExit(f"next exited {code}")
        if k:
            walls.append(time.perf_counter() - started)
            rss.append(int(peak) / 1024)
    return walls, rss


def with_gun(archive, lot, others, rng):
    """``others`` lots of the gun GUN-1 beside ``lot`` in ``archive``: each a copy of the
    lot's latest proposal (through the archive's own store) naming the gun, with the launch
    velocities of 5 shots drawn at the gun's scatter, as next --gun keeps them."""
    from airgun_xl.archive.lots import proposals, store_proposal

    record = dict(proposals(archive, lot)[-1][1])
    for k in range(others):
        shots = [{**record["shots"][0], "shot_sha256": f"{k:032x}{j:032x}"} for j in range(5)]
        launch = [{"shot_sha256": s["shot_sha256"], "recording_sha256": s["recording_sha256"],
                   "speed_m_s": 240.0, "factor": 1 + GUN * rng.normal(), "error": 0.004}
                  for s in shots]
        store_proposal(archive, f"LOT-G{k:03d}", {**record, "lot": f"LOT-G{k:03d}",
                                                  "shots": shots, "gun_name": "GUN-1",
                                                  "launch": launch})


def call(quick):
    """``next`` on a lot of 5 recorded shots, as a whole process: (label, wall [s], peak RSS
    [MB]) alone, with --vary E13 and with --gun among other lots of the gun."""
    rng = np.random.default_rng(7)
    law = true_law(rng)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        shot = with_velocity(work / "s0.xlsx", 240.0)
        for k in range(4):  # four shots of the lot recorded through next
            rec = fire(shot, law, (rng.normal(), rng.normal(), k), work / f"r{k}.csv")
            shot = airgun_xl.next_shot(shot, rec, archive=work / "archive", lot="LOT-T",
                                       new_lot=k == 0, sd=f"A28={GUN:.1%}", shots=200,
                                       output=work / f"s{k + 1}.xlsx", **SPEC).output
        rec = fire(shot, law, (rng.normal(), rng.normal(), 4), work / "r4.csv")
        base = [sys.executable, "-m", "airgun_xl", "next", str(shot), str(rec), "--archive",
                str(work / "archive"), "--lot", "LOT-T", "--sd", f"A28={GUN:.1%}", "--sd",
                f"E43={ZETA:.0%}",
                "--peak", SPEC["peak"], "--duration", SPEC["duration"], "-o",
                str(work / "n.xlsx"), "--force", "--quiet"]
        if quick:
            base += ["--shots", "200"]
        others = 3 if quick else 199
        with_gun(work / "archive", "LOT-T", others, rng)
        for label, extra in (("next, a lot of 5 shots", []),
                             ("next --vary E13, a lot of 5 shots", ["--vary", "E13"]),
                             (f"next --gun, {others} other lots of the gun", ["--gun", "GUN-1"])):
            walls, rss = timed(base + extra, 1 if quick else 5)
            rows.append((label, statistics.median(walls), max(rss)))
        # the same options on a lot spread over speed
        spread = [*base[:3], *spread_lot(work / "spread", law, rng),
                  *base[base.index("--sd"):]]
        walls, rss = timed(spread, 1 if quick else 5)
        rows.append(("next, 5 shots at 205-252 m/s (whole law)", statistics.median(walls),
                     max(rss)))
    return rows


def spread_lot(work, law, rng):
    """A lot of 4 shots at 205, 220, 232 and 244 m/s recorded (its proposal through the
    archive's own store, each file by its SHA-256) and a fifth at 252 m/s: the arguments of
    next on the fifth, the law fitted whole and tested (from 3 shots spread over speed)."""
    import hashlib

    from airgun_xl.archive.lots import proposals, store_proposal

    work.mkdir()
    files = []
    for k, v in enumerate((205.0, 220.0, 232.0, 244.0, 252.0)):
        shot = with_velocity(work / f"s{k}.xlsx", v)
        files.append((shot, fire(shot, law, (rng.normal(), rng.normal(), k), work / f"r{k}.csv")))
    archive = work / "archive"
    airgun_xl.next_shot(*files[0], archive=archive, lot="LOT-W", new_lot=True,
                        sd=f"A28={GUN:.1%}", shots=200, output=work / "n0.xlsx", **SPEC)
    record = dict(proposals(archive, "LOT-W")[-1][1])
    record["shots"] = [{"shot": str(s), "recording": str(r), "sign": 1.0,
                        "shot_sha256": hashlib.sha256(s.read_bytes()).hexdigest(),
                        "recording_sha256": hashlib.sha256(r.read_bytes()).hexdigest()}
                       for s, r in files[:4]]
    store_proposal(archive, "LOT-W", record)
    return ["next", str(files[4][0]), str(files[4][1]), "--archive", str(archive), "--lot",
            "LOT-W"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lots", type=int, default=200)
    parser.add_argument("--draws", type=int, default=1000, help="next's draws a setting")
    parser.add_argument("--vary", metavar="CELL", help="next's second knob (E13, E16, A2)")
    parser.add_argument("--gun", action="store_true",
                        help="every lot in one archive, next --gun: the gun's scatter pooled "
                             "over the lots once they hold 7 shots beyond each lot's first")
    parser.add_argument("--call", action="store_true",
                        help="time one next on a lot of 5 shots as a whole process")
    parser.add_argument("--gun-bias", type=float, default=0.0, metavar="F",
                        help="the gun's mean offset, e.g. -0.02: 2 %% slow (default 0)")
    parser.add_argument("--curvature", type=float, default=0.0, metavar="F",
                        help="the spread of a bend of each lot's law with speed, "
                             "(1 + c ((v - 240) / 240)^2), that scale and tilt cannot take")
    parser.add_argument("--rate", type=float, default=RECORDER.rate, metavar="HZ",
                        help="the recorder's rate (default 51,200; its anti-alias a fifth)")
    parser.add_argument("--replicates", type=int, default=3,
                        help="more shots fired from each proposal, each judged: the bands of "
                             "predicted P(PASS) get enough shots to be judged (default 3)")
    parser.add_argument("--dump", metavar="FILE.json",
                        help="also write every shot fired from a proposal (lot, place, "
                             "P(PASS), verdict, the model error drawn, positions) as JSON")
    parser.add_argument("--quick", action="store_true",
                        help="one lot, 200 draws: shows the benchmark runs, measures nothing")
    args = parser.parse_args()
    if args.call:
        rows = call(args.quick)
        print(f"machine: {machine()}")
        print("--quick: one repeat on a small case; these figures measure nothing\n"
              if args.quick else "median of 5 runs after a warm-up, 2,000 draws a setting\n")
        for label, wall, rss in rows:
            judged = ("not judged (--quick)" if args.quick else
                      "met" if wall <= 10 and rss <= 1024 else "NOT met")
            print(f"{label:<36} {wall:6.2f} s  {rss:6.0f} MB  (target 10 s, 1 GB: {judged})")
        return 0
    LAB.update(bias=args.gun_bias, curvature=args.curvature,
               recorder=dataclasses.replace(RECORDER, rate=args.rate))
    lots, n_draws = (1, 200) if args.quick else (args.lots, args.draws)
    started = time.perf_counter()
    first, p_first = first_setting(max(n_draws, 400))
    results = {"next": [], "by hand": []}
    honest_record, calls = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for lot in range(lots):
            rng = np.random.default_rng(1000 + lot)
            law = true_law(rng)
            draws = [(rng.normal(), rng.normal(), int(rng.integers(1 << 30)))
                     for _ in range(MOST_SHOTS)]
            work = Path(tmp) / f"lot{lot}"
            work.mkdir()
            shots, record = with_next(lot, law, first, work, draws, n_draws, calls,
                                      args.vary, "GUN-1" if args.gun else None,
                                      1 if args.quick else args.replicates)
            results["next"].append(shots)
            honest_record += record
            results["by hand"].append(by_hand(lot, law, first, work, draws))
    rows = [("method", "by 1st", "by 2nd", "by 3rd", "mean shots", "target")]
    share = {m: [np.mean(np.array(r) <= k) for k in (1, 2, 3)] for m, r in results.items()}
    as_good = all(a >= b for a, b in zip(share["next"], share["by hand"], strict=True))
    for method, found in results.items():
        target = ("not judged (--quick)" if args.quick else
                  f">= 90 % by 2nd: {'met' if share['next'][1] >= 0.9 else 'NOT met'}; "
                  f"at least by hand's at every count: {'met' if as_good else 'NOT met'}"
                  if method == "next" else "")
        rows.append((method, *(f"{s:.1%}" for s in share[method]),
                     f"{statistics.mean(found):.2f}", target))
    print(f"machine: {machine()}")
    print("--quick: one repeat on a small case; these figures measure nothing\n" if args.quick
          else f"{lots} lots, next with {n_draws:,} draws a setting; the first shot at "
               f"{first:.2f} m/s (design --confidence: P(PASS) {p_first:.3f} on the nominal "
               f"law); {time.perf_counter() - started:.0f} s, next"
               f"{f' --vary {args.vary}' if args.vary else ''}"
               f"{' --gun' if args.gun else ''} "
               f"{statistics.median(c for c, _, _ in calls):.2f} s a call (median); the lab: "
               f"gun offset {args.gun_bias:+.1%}, law bend spread {args.curvature:.0%}, "
               f"recorder {args.rate:,.0f} Hz\n")
    widths = [max(len(r[i]) for r in rows) for i in range(6)]
    for r in rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)))
    if REFUSED:
        lot, k, why = REFUSED[0]
        print(f"\nnext refused {len(REFUSED)} lot(s) (counted as never passed by next); the "
              f"first, lot {lot} at its shot {k}: {why}")
    updates = [u for _, _, u in calls]
    print(f"\nthe law's updates: {sum(not u.tilted for u in updates)} a scale, "
          f"{sum(u.tilted and not u.is_whole for u in updates)} a scale and tilt "
          f"({sum(u.shape is not None and not u.is_whole for u in updates)} of them tested "
          f"against the law fitted whole), {sum(u.is_whole for u in updates)} the law whole")
    for _, _, u in calls:
        if u.shape is not None:
            chi, dof, p = u.shape
            print(f"  tested: {u.shots} shots at {u.speeds[0]:.1f} to {u.speeds[1]:.1f} m/s, "
                  f"scale {u.scale:.4f}, tilt {u.tilt:+.4f}: chi-square {chi:.3g} on {dof}, "
                  f"p {p:.2g}{' (the law whole)' if u.is_whole else ''}; nodes' half-widths "
                  + ", ".join(f"{n.velocity:.0f}:{n.half_width:.1%}" for n in u.nodes)
                  + "; shifts in standard errors "
                  + ", ".join(f"{(u.law(n.velocity) - n.value) / n.error:+.1f}"
                              if not u.is_whole else "-" for n in u.nodes))
    if args.gun:
        pooled = [words for _, words, _ in calls if "as given" not in words]
        print(f"\nnext --gun: {len(calls) - len(pooled)} calls drew the scatter given, "
              f"{len(pooled)} the pooled estimate; the last: "
              f"{pooled[-1] if pooled else 'none'}")
    if CENTRES:
        print(f"\ncentring, {len(CENTRES)} proposals fired (with {args.replicates} replicates "
              "each): the share in the middle half of each tolerance, and the mean position "
              "(-1 and 1 the limits)")
        for name in TOLERANCES:
            exp = [c["expected"][name] for c in CENTRES if name in c["expected"]]
            got = [m[name] for c in CENTRES for m in c["measured"] if name in m]
            print(f"  {name}: expected {np.mean(np.abs(exp) <= 0.5):.1%} in the middle half "
                  f"(mean {np.mean(exp):+.2f}); measured {np.mean(np.abs(got) <= 0.5):.1%} "
                  f"(mean {np.mean(got):+.2f}, {len(got)} shots)")
    if honest_record:
        predicted, passed = zip(*honest_record, strict=True)
        print(f"\nnext's predictions, {len(predicted)} shots fired from its proposals "
              f"({args.replicates} replicates with each): Brier "
              f"{brier(predicted, passed):.4f}")
        for band in reliability(predicted, passed):
            if band.shots:
                lo, hi = band.interval
                judged = ("not judged (--quick)" if args.quick else
                          "honest" if band.honest else
                          "NOT honest" if band.shots >= 30 else "under 30 shots: not judged")
                print(f"  P(PASS) {band.low:.2f}-{band.high:.2f}: {band.shots} shots, mean "
                      f"predicted {band.mean_predicted:.3f}, passed {band.rate:.3f} "
                      f"[{lo:.3f}, {hi:.3f}]: {judged}")
    if args.dump:
        import json

        Path(args.dump).write_text(json.dumps(SHOTS, indent=0))
    return 0


if __name__ == "__main__":
    sys.exit(main())
