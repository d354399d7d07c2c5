"""nsgraph.progress: the Python side of the one progress reporter (docs/cli.md "Progress")."""
import io
import unittest

from nsgraph.progress import Progress


class Clock:
    """Seconds that the test advances by hand: no test waits on real time."""

    def __init__(self):
        self.s = 0.0

    def __call__(self):
        return self.s


class Terminal(io.StringIO):
    def isatty(self):
        return True


class ProgressTest(unittest.TestCase):
    def test_a_log_gets_a_line_every_interval_and_a_final_one_never_a_carriage_return(self):
        out, clock = io.StringIO(), Clock()
        bar = Progress("predict test", 1000, stream=out, interval_s=5.0, clock=clock)
        for _ in range(1000):
            clock.s += 0.125  # 125 s in all (exact in binary): a line every 5 s, 25 of them
            bar.advance()
        bar.finish()
        lines = out.getvalue().splitlines()
        self.assertNotIn("\r", out.getvalue())
        self.assertEqual(len(lines), 26, lines)  # 25 interval lines and the final one
        self.assertEqual(lines[-1], "predict test: 1000/1000 (100%) 125.0s, ETA 0s")
        self.assertEqual(lines[0], "predict test: 40/1000 (4%) 5.0s, ETA 120s")

    def test_a_terminal_gets_one_line_redrawn_in_place(self):
        out, clock = Terminal(), Clock()
        with Progress("train steps", 3, stream=out, clock=clock) as bar:
            for _ in range(3):
                clock.s += 1.0
                bar.set_detail("epoch 0 heat 0.500")
                bar.advance()
        text = out.getvalue()
        self.assertEqual(text.count("\r\033[K"), 4)  # three redraws and the final one
        self.assertTrue(text.endswith("train steps: 3/3 (100%) 3.0s, ETA 0s, epoch 0 heat 0.500\n"), repr(text))
        self.assertEqual(text.count("\n"), 1)

    def test_quiet_and_unknown_totals_and_one_final_line(self):
        out = io.StringIO()
        with Progress("x", 10, enabled=False, stream=out) as bar:
            bar.advance(10)
        self.assertEqual(out.getvalue(), "")
        clock = Clock()
        bar = Progress("sweeps", stream=out, clock=clock)
        bar.advance(7)
        clock.s = 2.0
        bar.finish()
        bar.finish()  # idempotent
        self.assertEqual(out.getvalue(), "sweeps: 7 2.0s\n")

    def test_a_stream_without_isatty_is_a_log(self):
        class Plain:
            def __init__(self):
                self.text = ""

            def write(self, s):
                self.text += s

            def flush(self):
                pass

        out = Plain()
        Progress("y", 1, stream=out).finish()
        self.assertEqual(out.text, "y: 0/1 (0%) 0.0s, ETA 0s\n")


if __name__ == "__main__":
    unittest.main()
