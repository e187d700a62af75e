"""``airgun-xl check SHOT.xlsx``: can this shot's run be trusted? (No run, no output.)"""
from .run_options import add_integrator


def add_parser(sub):
    p = sub.add_parser("check", help="predict stability and list the model's limits for a shot",
                       description="Predict the critical time step of the chosen scheme and "
                                   "list what the shot stretches (crush-factor range, filter, "
                                   "row count, masses). Exit 0 when it can run, 2 when the "
                                   "time step is unstable.")
    p.add_argument("shot", metavar="SHOT.xlsx", help="workbook in the report's layout")
    add_integrator(p)
    p.set_defaults(run=run)


def run(args):
    from pathlib import Path

    from ..app.check import CheckRequest
    from ..app.check import run as check

    outcome = check(CheckRequest(Path(args.shot), args.integrator))
    p, crit = outcome.params, outcome.critical
    print(f"{args.shot}: {p.model}, {args.integrator} integrator")
    print(f"  time step E2 = {p.delta:.4g} s, critical {crit.dt_crit:.4g} s for the OBR chain "
          f"(the springs that always act), ratio {crit.ratio:.3g}: {crit.verdict}")
    print(f"  set by {crit.limiting}")
    print(f"  while the mitigator unloads: critical {crit.dt_unloading:.4g} s at full length "
          f"{outcome.full_length:.4g} m, {crit.dt_compacted:.4g} s fully compacted (length "
          f"{outcome.compacted_length:.4g} m, E37 = {p.ec:g})")
    if crit.unstable_crush is not None:
        print(f"  unstable while unloading once crushed by {crit.unstable_crush:.4g} m (length "
              f"below {crit.unstable_length:.4g} m): the run is watched and stops where it "
              "diverges")
    for message in outcome.warnings:
        print(f"  warning: {message}")
    for f in outcome.findings:
        print(f"  {f.level}: {f}")
    return 0 if outcome.stable else 2
