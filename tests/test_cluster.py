"""Issue 13: studies on a Dask cluster give the local run's figures, in order, whatever the
chunking, and survive a worker killed mid-run (distributed.LocalCluster, 2 worker processes)."""
import os
import signal

import numpy as np
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.engine.batch import run_batch
from airgun_xl.studies.cluster import ClusterRunner, connect

distributed = pytest.importorskip("distributed")

SHOT = airgun_xl.load(TEMPLATE).params


@pytest.fixture(scope="module")
def client():
    client, close = connect(workers=2)
    yield client
    close()


def _shots(n, **changes):
    base = SHOT.replace(**changes)
    return [base.replace(v31=v, v32=v, v33=v, sigmay=s)
            for v, s in zip(np.linspace(80, 260, n), np.linspace(2.5e7, 2.9e7, n), strict=True)]


def _same(a, b):
    return np.array_equal(a.figures, b.figures, equal_nan=True) and np.array_equal(
        a.diverged, b.diverged) and a.stats == b.stats  # the flags' statistics come back too


@pytest.mark.parametrize("chunk", [1, 7, 64, 1000])
def test_same_figures_in_the_same_order_whatever_the_chunking(client, chunk):
    shots = _shots(40)
    local = run_batch(shots)
    assert _same(ClusterRunner(client, chunk)(shots), local)


def test_diverged_lanes_come_back_marked(client):
    """Shots with a stiff k3 at 5 us diverge: marked, NaN figures, the others unaffected."""
    shots = _shots(6, delta=5e-6) + [SHOT.replace(k3=-5e11, delta=5e-6)] * 2
    local = run_batch(shots)
    remote = ClusterRunner(client, 3)(shots)
    assert _same(remote, local) and remote.diverged.tolist() == [False] * 6 + [True] * 2


def test_sweep_cli_on_workers_writes_the_local_table(tmp_path, capsys):
    import openpyxl

    here, there = tmp_path / "here.xlsx", tmp_path / "there.xlsx"
    args = ["sweep", str(TEMPLATE), "--vary", "A28=100:260:9", "--vary", "E40=2.5e7:2.9e7:3"]
    assert main([*args, "-o", str(here)]) == 0
    assert main([*args, "-o", str(there), "--workers", "2", "--chunk", "4"]) == 0
    read = [list(openpyxl.load_workbook(p, read_only=True)["Sweep"].iter_rows(
        values_only=True)) for p in (here, there)]
    assert read[0] == read[1] and len(read[0]) > 27


def test_design_on_a_cluster_finds_the_same_v0(client):
    from airgun_xl.studies.design import VARIABLES, solve_peak

    local = solve_peak(SHOT, 8.0, VARIABLES["A28"])
    remote = solve_peak(SHOT, 8.0, VARIABLES["A28"], runner=ClusterRunner(client, 4))
    assert remote.values == local.values and remote.evaluations == local.evaluations


def test_a_worker_killed_mid_run_costs_nothing():
    """SIGKILL one of two workers once a quarter of the shots are back: Dask runs its chunks
    again elsewhere (the nanny restarts it), and every shot is counted once with the local
    figures. 240 shots of shot A at 50 ns (120k rows each), chunks of 6."""
    client, close = connect(workers=2)
    try:
        shots = _shots(240, delta=5e-8)
        done = {"shots": 0, "killed": None}

        def progress(n):
            done["shots"] += n
            if done["killed"] is None and done["shots"] >= 60:
                pids = client.run(os.getpid)
                address, pid = sorted(pids.items())[0]
                os.kill(pid, signal.SIGKILL)
                done["killed"] = address

        remote = ClusterRunner(client, 6)(shots, progress=progress)
        assert done["killed"] is not None and done["shots"] == 240
        assert _same(remote, run_batch(shots))
    finally:
        close()


def test_cluster_options_are_checked(tmp_path, capsys):
    out = tmp_path / "o.xlsx"
    args = ["sweep", str(TEMPLATE), "--vary", "A28=100:260:3", "-o", str(out)]
    assert main([*args, "--chunk", "5"]) == 2
    assert main([*args, "--workers", "0"]) == 2
    assert main([*args, "--scheduler", "tcp://127.0.0.1:9"]) == 2
    errors = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    assert errors[0].startswith("airgun-xl: error: --chunk: found it without --scheduler")
    assert errors[1].startswith("airgun-xl: error: --workers: found 0")
    assert errors[2].startswith("airgun-xl: error: --scheduler: found 'tcp://127.0.0.1:9', "
                                "which did not answer")
    assert len(errors) == 3 and not out.exists()


def test_a_pass_probability_on_the_cluster_equals_the_batch_lanes(client):
    """Issue 25: design --confidence's Monte Carlo on Dask workers (the judge pickled to them)
    passes and fails the same shots as on this machine's lanes."""
    from airgun_xl.specification import Specification, Tolerance
    from airgun_xl.studies.design import variable
    from airgun_xl.studies.first_shot import pass_probability
    from airgun_xl.studies.sweep import parse_sd

    p = airgun_xl.load(TEMPLATE).params
    # shot A's record judged at 242 m/s: 8.36 kG, 5.22 ms (the default low-pass)
    spec = Specification(peak=Tolerance(8.4, 0.05, 0.05), duration=Tolerance(5.2e-3, 0.1, 0.1))
    sds = [parse_sd("A28=1.5%"), parse_sd("E40=5%")]
    local = pass_probability(p, spec, sds, 300, 3, variable("A28"), 242.0)
    remote = pass_probability(p, spec, sds, 300, 3, variable("A28"), 242.0,
                              runner=ClusterRunner(client, chunk=64))
    assert (remote.passes, remote.failures) == (local.passes, local.failures)
    assert 0 < local.passes < 300


def test_next_on_the_cluster_proposes_what_it_proposes_on_the_lanes(client, tmp_path):
    """Issue 45: next's draws on Dask workers (--scheduler) are the same shots judged the
    same way: the same setting, the same passes, the same P(PASS), to the bit."""
    from conftest import write_trace_csv

    from airgun_xl.crush_law import LEGACY_LAW
    from airgun_xl.studies.calibrate import synthetic_measurement

    p = SHOT.replace(crush_law=LEGACY_LAW.scaled(1.1))
    write_trace_csv(tmp_path / "rec.csv", synthetic_measurement(p, dt=1 / 51_200, seed=3))
    found = []
    for where in ("lanes", "cluster"):
        found.append(airgun_xl.next_shot(
            TEMPLATE, tmp_path / "rec.csv", archive=tmp_path / where, lot="LOT-C",
            new_lot=True, sd=["A28=1.5%"], shots=200, output=tmp_path / f"{where}.xlsx",
            scheduler=client.scheduler.address if where == "cluster" else None,
            chunk=64 if where == "cluster" else None, peak="8.5kG:5%", duration="4.5ms:15%"))
    lanes, cluster = found
    assert (cluster.setting, cluster.best.passes, cluster.best.failures) == (
        lanes.setting, lanes.best.passes, lanes.best.failures)
    assert 0 < lanes.best.passes  # a setting that passes at all: the comparison means something
