"""The Python API against the same physics and the same files as the command line.

Run from the checkout root: python -m unittest discover -s python/tests
"""

import concurrent.futures
import csv
import json
import multiprocessing
import shutil
import tempfile
import unittest
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

import rheosph

ROOT = Path(__file__).resolve().parents[2]
POISEUILLE = ROOT / "cases" / "poiseuille.toml"
# A coarse, short start-up Poiseuille flow (Oldroyd-B, Re = Wi = 1, beta = 0.1): 144
# particles, about 2 s.
QUICK = {"scene.resolution": 12, "run.end_time": 0.3, "run.output_interval": 0.01}


class RunTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.progress = []
        cls.result = rheosph.run(
            POISEUILLE,
            out=Path(cls.tmp.name) / "p",
            overrides=QUICK,
            progress=lambda t, end: cls.progress.append((t, end)),
        )

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_series_maps_every_column_of_series_csv_to_an_array(self):
        header = (self.result.path / "series.csv").read_text().splitlines()[0].split(",")
        series = self.result.series
        self.assertEqual(list(series), header)
        rows = len((self.result.path / "series.csv").read_text().splitlines()) - 1
        for name in header:
            self.assertIsInstance(series[name], np.ndarray)
            self.assertEqual(series[name].shape, (rows,))
        self.assertEqual(series["t"][0], 0.0)
        self.assertAlmostEqual(series["t"][-1], 0.3, places=9)

    def test_the_run_follows_waters_king(self):
        # H/dr = 12 is the coarsest channel allowed: the centre-line velocity stays within
        # 1.5 % of the series (measured) and the L2 error, dominated by the rows next to the
        # walls, grows to 0.099 U by t = 0.3 (measured); bounds 3 % and 0.15 U.
        s = self.result.series
        self.assertEqual(self.result.outcome, "finished")
        self.assertEqual(self.result.exit_code, 0)
        self.assertLess(np.nanmax(s["l2_error"]), 0.15)
        np.testing.assert_allclose(s["u_centre"][5:], s["u_centre_exact"][5:], rtol=0.03)
        self.assertAlmostEqual(
            self.result.summary["errors"]["l2_max"], float(np.max(s["l2_error"])), places=6
        )

    def test_progress_is_called_at_every_row_up_to_the_end(self):
        times = [t for t, _ in self.progress]
        self.assertGreaterEqual(len(times), 25)
        self.assertTrue(all(b > a for a, b in zip(times, times[1:])))
        self.assertAlmostEqual(times[-1], 0.3, places=9)
        self.assertTrue(all(end == 0.3 for _, end in self.progress))

    def test_particles_and_grid_of_the_final_state(self):
        p = self.result.particles()
        n = self.result.summary["particles"]
        for name in ("x", "y", "u", "v", "pressure", "tau_xx", "tau_xy", "tau_yy", "det_A"):
            self.assertEqual(p[name].shape, (n,), name)
        # profile.csv holds the same particles' velocities (written from the same state).
        profile = self.result.profile
        np.testing.assert_allclose(np.sort(p["u"]), np.sort(profile["u"]), rtol=1e-8)
        g = self.result.grid()
        self.assertEqual(g.fields["u"].shape, (len(g.y), len(g.x)))
        # A channel is fluid wall to wall; the grid's u at a height is the particles'
        # u there (the profile is ~ parabolic: the quadratic fit is near exact).
        self.assertTrue(np.all(g.fields["fluid"] == 1.0))
        row = np.argmin(abs(g.y - 0.5))
        near = abs(p["y"] - g.y[row]) < 0.25 / 12
        self.assertTrue(near.any())
        self.assertAlmostEqual(float(np.mean(g.fields["u"][row])), float(np.mean(p["u"][near])), delta=0.02)

    def test_open_run_reads_the_same_directory(self):
        again = rheosph.open_run(self.result.path)
        self.assertEqual(again.summary, self.result.summary)
        np.testing.assert_array_equal(again.series["u_centre"], self.result.series["u_centre"])

    def test_continuation_from_the_final_state(self):
        # Twice the relaxation time from the state at t = 0.3: the clock restarts at 0 and
        # the first row carries the previous run's last velocity.
        out = Path(self.tmp.name) / "continued"
        r = rheosph.run(
            POISEUILLE,
            out=out,
            overrides={**QUICK, "run.end_time": 0.1, "fluid.relaxation_time": 2.0},
            from_run=self.result,
        )
        self.assertEqual(r.outcome, "finished")
        self.assertEqual(r.series["t"][0], 0.0)
        self.assertAlmostEqual(r.series["u_centre"][0], self.result.series["u_centre"][-1], places=12)


class CaseTest(unittest.TestCase):
    def test_bad_input_raises_the_command_lines_one_line(self):
        with self.assertRaises(rheosph.CaseError) as e:
            rheosph.load_case(POISEUILLE, {"fluid.beta": 2})
        message = str(e.exception)
        self.assertIn("poiseuille.toml", message)
        self.assertIn("fluid.beta", message)
        self.assertEqual(len(message.splitlines()), 1)
        with self.assertRaises(rheosph.CaseError) as e:
            rheosph.load_case({"scene": {"kind": "channel"}})
        self.assertIn("fluid", str(e.exception))

    def test_a_dict_case_is_the_file_case(self):
        import tomllib

        table = tomllib.loads(POISEUILLE.read_text())
        from_dict = rheosph.load_case(table, QUICK)
        from_file = rheosph.load_case(POISEUILLE, QUICK)
        self.assertEqual(from_dict.derived, from_file.derived)
        self.assertEqual(from_file.derived["weissenberg"], 1.0)

    def test_a_progress_exception_is_raised_after_the_run(self):
        def fail(t, end):
            raise KeyError("from the callback")

        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaises(KeyError):
                rheosph.run(POISEUILLE, out=Path(tmp) / "p", overrides={**QUICK, "run.end_time": 0.02}, progress=fail)
            # The run itself finished and wrote its summary.
            summary = json.loads((Path(tmp) / "p" / "summary.json").read_text())
            self.assertEqual(summary["outcome"], "finished")


class RheometryAndStudyTest(unittest.TestCase):
    def test_oldroyd_b_steady_shear_material_functions(self):
        # Oldroyd-B: eta = eta0 = 1 and Psi1 = 2 eta_p lambda = 1.8 at every rate; the
        # integration to steady state is within 5e-4 of them (measured), bound 1e-3.
        with tempfile.TemporaryDirectory() as tmp:
            m = rheosph.rheometry(POISEUILLE, Path(tmp) / "rh")
            steady = m["steady_shear"]
            np.testing.assert_allclose(steady["viscosity_exact"], 1.0, rtol=1e-12)
            np.testing.assert_allclose(steady["viscosity"], 1.0, rtol=1e-3)
            np.testing.assert_allclose(steady["psi1"], 2 * 0.9 * 1.0, rtol=1e-3)
            self.assertIn("saos", m)

    def test_convergence_study_returns_its_table(self):
        with tempfile.TemporaryDirectory() as tmp:
            table = rheosph.study(
                "convergence",
                POISEUILLE,
                Path(tmp) / "conv",
                overrides={"run.end_time": 0.2},
                resolutions=[12, 24],
            )
            self.assertEqual(list(table["resolution"]), [12.0, 24.0])
            # Refinement reduces the error (first-order at least at these resolutions).
            self.assertLess(table["l2_mean"][1], table["l2_mean"][0])
            self.assertTrue((Path(tmp) / "conv" / "l2_vs_resolution.png").exists())


class _Inline(concurrent.futures.Executor):
    """Runs each call at once in this process; loses the calls numbered in `lose` as a
    killed worker would (the executor's BrokenProcessPool), and spoils the case file of the
    members numbered in `fail` first, so that their runs stop on an error."""

    def __init__(self, lose=(), fail=()):
        self.lose, self.fail, self.calls = set(lose), set(fail), 0

    def submit(self, fn, /, *args, **kwargs):
        future = concurrent.futures.Future()
        self.calls += 1
        if self.calls in self.fail:
            (Path(args[0]) / "case.toml").write_text("[scene\n")
        try:
            if self.calls in self.lose:
                raise BrokenProcessPool("a worker was killed")
            future.set_result(fn(*args, **kwargs))
        except Exception as e:
            future.set_exception(e)
        return future


class StudyExecutorTest(unittest.TestCase):
    ARGS = dict(overrides={"run.end_time": 0.5, "scene.resolution": 12}, wi=[0.5, 2])

    def assert_same_table(self, a, b):
        self.assertEqual(sorted(a), sorted(b))
        for column in a:
            if column != "wall_seconds":
                np.testing.assert_array_equal(a[column], b[column], err_msg=column)

    def test_a_process_pool_gives_the_study_run_here(self):
        spawn = multiprocessing.get_context("spawn")
        with tempfile.TemporaryDirectory() as tmp:
            here = rheosph.study("stability", POISEUILLE, Path(tmp) / "here", **self.ARGS)
            with concurrent.futures.ProcessPoolExecutor(2, mp_context=spawn) as pool:
                there = rheosph.study(
                    "stability", POISEUILLE, Path(tmp) / "pool", executor=pool, **self.ARGS
                )
            self.assert_same_table(here, there)

    def test_a_dask_cluster_gives_the_study_run_here(self):
        # dask.distributed is installed in the test environment from PyPI (the package's
        # `dask` extra), as a user would; two worker processes, one thread each.
        from dask.distributed import Client, LocalCluster

        with tempfile.TemporaryDirectory() as tmp:
            here = rheosph.study("stability", POISEUILLE, Path(tmp) / "here", **self.ARGS)
            cluster = LocalCluster(
                n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
            )
            with cluster, Client(cluster) as client:
                there = rheosph.study(
                    "stability",
                    POISEUILLE,
                    Path(tmp) / "dask",
                    executor=client.get_executor(),
                    **self.ARGS,
                )
            self.assert_same_table(here, there)

    def test_a_failed_member_of_a_study_run_here_is_a_row_and_reuse_reruns_it_alone(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "s"
            # Its run cannot write series.csv: a directory stands in its place.
            blocked = out / "runs" / "Wi_2" / "series.csv"
            blocked.mkdir(parents=True)
            with self.assertRaises(rheosph.StudyIncomplete) as failed:
                rheosph.study("stability", POISEUILLE, out, jobs=2, **self.ARGS)
            self.assertEqual(sorted(failed.exception.failed), ["runs/Wi_2"])
            with open(failed.exception.table, newline="") as f:
                rows = {r["wi"]: r for r in csv.DictReader(f)}
            self.assertEqual(rows["2"]["outcome"], "failed")
            self.assertIn(rows["0.5"]["outcome"], ("stable", "inaccurate"))
            first = out / "runs" / "Wi_0.5" / "summary.json"
            stamp = first.stat().st_mtime_ns
            blocked.rmdir()
            table = rheosph.study("stability", POISEUILLE, out, reuse=True, **self.ARGS)
            self.assertEqual(first.stat().st_mtime_ns, stamp, "a finished member was rerun")
            self.assertIn(table["outcome"][1], ("stable", "inaccurate"))

    def test_lost_and_failed_members_are_rows_and_a_rerun_completes_only_them(self):
        args = dict(self.ARGS, wi=[0.5, 1, 2])
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "s"
            with self.assertRaises(rheosph.StudyIncomplete) as lost:
                rheosph.study(
                    "stability", POISEUILLE, out, executor=_Inline(lose={2}, fail={3}), **args
                )
            failed = lost.exception.failed
            self.assertEqual(sorted(failed), ["runs/Wi_1", "runs/Wi_2"])
            self.assertIn("BrokenProcessPool", failed["runs/Wi_1"])
            self.assertIn("RuntimeError", failed["runs/Wi_2"])
            # The table is written all the same: a row per member, the missing ones marked.
            self.assertEqual(lost.exception.table, out / "stability.csv")
            with open(lost.exception.table, newline="") as f:
                rows = {r["wi"]: r for r in csv.DictReader(f)}
            self.assertEqual(sorted(rows), ["0.5", "1", "2"])
            self.assertIn(rows["0.5"]["outcome"], ("stable", "inaccurate"))
            self.assertEqual(rows["1"]["outcome"], "lost")
            self.assertEqual(rows["2"]["outcome"], "failed")
            self.assertIn("case.toml", rows["2"]["reason"])
            self.assertEqual(rows["1"]["l2_mean"], "")
            first = out / "runs" / "Wi_0.5" / "summary.json"
            stamp = first.stat().st_mtime_ns
            table = rheosph.study("stability", POISEUILLE, out, executor=_Inline(), **args)
            self.assertEqual(first.stat().st_mtime_ns, stamp, "a finished member was rerun")
            here = rheosph.study("stability", POISEUILLE, Path(tmp) / "here", **args)
            self.assert_same_table(here, table)


class SimulationTest(unittest.TestCase):
    def series(self, path):
        return (Path(path) / "series.csv").read_text()

    def test_stepped_from_python_it_writes_the_command_lines_series(self):
        with tempfile.TemporaryDirectory() as tmp:
            cli = rheosph.run(POISEUILLE, Path(tmp) / "cli", overrides=QUICK)
            sim = rheosph.Simulation(POISEUILLE, Path(tmp) / "py", overrides=QUICK)
            steps = 0
            while sim.step():
                steps += 1
            self.assertEqual(steps, sim.steps)
            self.assertGreater(steps, 100)
            fields = sim.particles()
            self.assertEqual(len(fields["x"]), 144)
            self.assertTrue(np.all(fields["det_A"] >= 1.0 - 1e-9))
            self.assertIn("A_xy", fields)
            result = sim.finish()
            self.assertEqual(result.outcome, "finished")
            self.assertEqual(self.series(cli.path), self.series(result.path))

    def test_a_checkpoint_resumes_bit_for_bit(self):
        with tempfile.TemporaryDirectory() as tmp:
            a = rheosph.Simulation(POISEUILLE, Path(tmp) / "a", overrides=QUICK)
            self.assertTrue(a.advance(0.1))
            self.assertGreaterEqual(a.t, 0.1)
            a.checkpoint()
            shutil.copytree(Path(tmp) / "a", Path(tmp) / "b")
            seen = []
            self.assertFalse(a.advance(1e9, progress=lambda t, target: seen.append(t)))
            self.assertGreater(len(seen), 10)
            a.finish()
            b = rheosph.Simulation.resume(Path(tmp) / "b")
            b.advance(1e9)
            b.finish()
            self.assertEqual(self.series(Path(tmp) / "a"), self.series(Path(tmp) / "b"))

    def test_a_body_force_is_validated_like_a_case_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            sim = rheosph.Simulation(POISEUILLE, Path(tmp) / "s", overrides=QUICK)
            with self.assertRaises(rheosph.CaseError) as bad:
                sim.set_body_force(float("nan"), 0.0)
            self.assertIn("scene.body_force", str(bad.exception))
            sim.set_body_force(0.0, 0.0)
            sim.advance(0.05)
            # Without the driving force the fluid at rest stays at rest.
            self.assertLess(np.abs(sim.particles()["u"]).max(), 1e-9)


def disc_in_channel(velocity=None, motion="prescribed"):
    """A plane Couette cell with one disc (R/dr = 8, the coarsest the set-up takes), as a
    dict case."""
    disc = {"radius": 1.0, "centre": [4.0, 4.0], "motion": motion}
    if velocity is not None:
        disc["velocity"] = velocity
    return {
        "scene": {
            "kind": "channel",
            "length": 8.0,
            "height": 8.0,
            "resolution": 64,
            "wall_velocity": [-1.0, 1.0],
            "discs": [disc],
        },
        "fluid": {"model": "newtonian", "density": 1.0, "viscosity": 1.0},
        "run": {"end_time": 0.06, "output_interval": 0.02},
    }


class SteeringTest(unittest.TestCase):
    def test_a_disc_steered_from_python_is_the_case_that_gives_its_velocity(self):
        with tempfile.TemporaryDirectory() as tmp:
            given = rheosph.run(disc_in_channel([0.3, 0.1]), Path(tmp) / "given")
            sim = rheosph.Simulation(disc_in_channel([0.0, 0.0]), Path(tmp) / "steered")
            sim.set_disc_motion(0, (0.3, 0.1))
            sim.advance(1e9)
            steered = sim.finish()
            self.assertEqual(given.outcome, "finished")
            self.assertEqual(
                (given.path / "series.csv").read_text(), (steered.path / "series.csv").read_text()
            )
            # disc.csv's row at t = 0 was written when the simulation was set up, before
            # the disc was steered; every row after it is the given case's.
            given_rows = (given.path / "disc.csv").read_text().splitlines()
            steered_rows = (steered.path / "disc.csv").read_text().splitlines()
            self.assertEqual(len(given_rows), len(steered_rows))
            self.assertGreater(len(given_rows), 3)
            self.assertEqual(given_rows[2:], steered_rows[2:])

    def test_steering_is_validated_like_a_case_key(self):
        with tempfile.TemporaryDirectory() as tmp:
            free = rheosph.Simulation(disc_in_channel(motion="free"), Path(tmp) / "free")
            with self.assertRaises(rheosph.CaseError) as bad:
                free.set_disc_motion(0, (0.1, 0.0))
            self.assertIn("scene.discs[0]", str(bad.exception))
            with self.assertRaises(rheosph.CaseError) as bad:
                free.set_disc_motion(3, (0.1, 0.0))
            self.assertIn("no disc 3", str(bad.exception))
            held = rheosph.Simulation(disc_in_channel([0.0, 0.0]), Path(tmp) / "held")
            with self.assertRaises(rheosph.CaseError):
                held.set_disc_motion(0, (float("inf"), 0.0))


class OutputsTest(unittest.TestCase):
    def test_outputs_written_mid_run_leave_the_run_unchanged(self):
        with tempfile.TemporaryDirectory() as tmp:
            cli = rheosph.run(POISEUILLE, Path(tmp) / "cli", overrides=QUICK)
            sim = rheosph.Simulation(POISEUILLE, Path(tmp) / "py", overrides=QUICK)
            sim.advance(0.1)
            sim.write_outputs(Path(tmp) / "now")
            now = rheosph.open_run(Path(tmp) / "now")
            self.assertEqual(len(now.profile["y"]), 144)
            self.assertGreater(len(now.series["t"]), 5)
            self.assertAlmostEqual(now.series["t"][-1], sim.t, delta=0.011)
            self.assertTrue((Path(tmp) / "now" / "state.vtu").read_bytes().startswith(b"<?xml"))
            sim.advance(1e9)
            self.assertEqual(
                (cli.path / "series.csv").read_text(),
                (sim.finish().path / "series.csv").read_text(),
            )

    def test_a_free_surface_scene_flags_its_surface_particles(self):
        with tempfile.TemporaryDirectory() as tmp:
            overrides = {"scene.resolution": 16, "run.end_time": 0.02}
            drop = ROOT / "cases" / "static-drop.toml"
            sim = rheosph.Simulation(drop, Path(tmp) / "drop", overrides=overrides)
            self.assertNotIn("free_surface", sim.particles())  # none before the first step
            sim.step()
            fields = sim.particles()
            surface = fields["free_surface"]
            self.assertTrue(set(np.unique(surface)) <= {0.0, 1.0})
            # The surface particles are the outermost: their mean radius exceeds the rest's.
            r = np.hypot(fields["x"] - fields["x"].mean(), fields["y"] - fields["y"].mean())
            self.assertGreater(surface.sum(), 10)
            self.assertGreater(r[surface == 1.0].mean(), r[surface == 0.0].max() - 0.2)
            self.assertIn("near_surface", fields)


PIPE = ROOT / "cases" / "pipe.toml"
# The 3D pipe at its coarsest (2R/dr = 12, 1356 particles), a few steps.
PIPE_QUICK = {"scene.resolution": 12, "run.end_time": 0.15, "run.output_interval": 0.05}


class ThreeDTest(unittest.TestCase):
    def series(self, path):
        return (Path(path) / "series.csv").read_text()

    def test_a_3d_simulation_steps_checkpoints_and_hands_over_its_arrays(self):
        with tempfile.TemporaryDirectory() as tmp:
            cli = rheosph.run(PIPE, Path(tmp) / "cli", overrides=PIPE_QUICK)
            sim = rheosph.Simulation(PIPE, Path(tmp) / "py", overrides=PIPE_QUICK)
            self.assertEqual(sim.dimension, 3)
            self.assertTrue(sim.advance(0.05))
            sim.checkpoint()
            shutil.copytree(Path(tmp) / "py", Path(tmp) / "resumed")
            fields = sim.particles()
            for name in ("z", "w", "tau_xz", "tau_zz", "A_yz", "trace_A"):
                self.assertIn(name, fields)
            self.assertEqual(len(fields["z"]), 1356)
            self.assertTrue(np.all(fields["det_A"] >= 1.0 - 1e-9))
            with self.assertRaises(rheosph.CaseError):
                sim.set_disc_motion(0, (0.0, 0.0))
            sim.advance(1e9)
            self.assertEqual(sim.finish().outcome, "finished")
            self.assertEqual(self.series(cli.path), self.series(Path(tmp) / "py"))
            resumed = rheosph.Simulation.resume(Path(tmp) / "resumed")
            self.assertEqual(resumed.dimension, 3)
            resumed.advance(1e9)
            resumed.finish()
            self.assertEqual(self.series(cli.path), self.series(Path(tmp) / "resumed"))
            final = cli.particles()
            self.assertEqual(len(final["z"]), 1356)
            # The axial velocity is the run's: no particle faster than the final centre line.
            self.assertLessEqual(final["u"].max(), 1.05 * cli.series["u_centre"][-1])

    def test_a_3d_body_force_takes_three_components(self):
        with tempfile.TemporaryDirectory() as tmp:
            sim = rheosph.Simulation(PIPE, Path(tmp) / "s", overrides=PIPE_QUICK)
            sim.set_body_force(0.0, 0.0, 0.0)
            sim.advance(0.05)
            # Without the driving force the fluid at rest stays at rest.
            self.assertLess(np.abs(sim.particles()["u"]).max(), 1e-9)
            with self.assertRaises(rheosph.CaseError):
                sim.set_body_force(0.0, 0.0, float("nan"))


class VersionTest(unittest.TestCase):
    def test_the_package_and_the_program_share_one_version(self):
        with tempfile.TemporaryDirectory() as tmp:
            result = rheosph.run(POISEUILLE, Path(tmp) / "v", overrides=QUICK, figure_format=None)
            self.assertEqual(rheosph.__version__, result.summary["version"])
        from importlib.metadata import version

        self.assertEqual(version("rheosph"), rheosph.__version__)


if __name__ == "__main__":
    unittest.main()
