"""The Python API against the same physics and the same files as the command line.

Run from the checkout root: python -m unittest discover -s python/tests
"""

import json
import tempfile
import unittest
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


if __name__ == "__main__":
    unittest.main()
