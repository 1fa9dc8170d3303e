"""Load-aware thread count: never much slower in parallel than serial on a busy machine.

OpenMP's static schedule makes every parallel loop wait for its slowest thread.  When
another process shares the cores, one of our threads is descheduled for a time slice
(milliseconds) and the whole pass waits: on 2 busy cores 2 threads ran 4x slower than one.
:class:`ThreadTuner` times steps with the requested threads and with one thread, keeps
the faster, and checks again at growing intervals (short again as soon as the choice
flips, since load comes and goes).  A trial that is clearly losing after its first
``early`` steps (every one slower than ``1 / margin`` of the current median) ends there,
so that on an idle machine the trials cost a few serial steps, not ``trial`` of them.  The loops compute each particle independently, so
the choice never changes the results.

A trial of fewer threads is only started when the machine is seen busy: the kernel's
count of runnable threads (``/proc/loadavg``) exceeds our own running thread.  On an
idle machine the trials are skipped, so they cost nothing there.
"""
import statistics


def others_running(path="/proc/loadavg"):
    """True if some thread besides the caller is runnable now (or if it cannot be told)."""
    try:
        with open(path) as f:
            running = int(f.read().split()[3].split("/")[0])
    except (OSError, ValueError, IndexError):
        return True
    return running > 1


class ThreadTuner:
    """Chooses, step by step, between ``scene.threads`` threads and one."""

    def __init__(self, scene, trial=6, first=20, longest=3200, early=2, margin=0.8):
        self.scene = scene
        self.most = scene.threads
        self.trial, self.first, self.longest = trial, first, longest
        self.early, self.margin = early, margin
        self.current = self.most
        self.every = first
        self._times = []          # step times of the current run phase
        self._trying = None       # (other count, its step times) during a trial
        self._steps = 0
        self.choices = []         # (step, threads) whenever the choice changes
        self.busy = others_running

    @property
    def active(self):
        return self.most > 1

    def record(self, step, seconds):
        """Account one step's wall time; may switch the thread count for the next step."""
        if not self.active:
            return
        if self._trying is not None:
            times = self._trying[1]
            times.append(seconds)
            losing = (len(times) == self.early
                      and min(times) * self.margin > statistics.median(self._times))
            if len(times) >= self.trial or losing:
                self._decide(step)
            return
        self._times = (self._times + [seconds])[-self.trial:]
        self._steps += 1
        if self._steps >= self.every and len(self._times) >= self.trial:
            other = 1 if self.current != 1 else self.most
            if other < self.current and not self.busy():
                self._steps = 0           # idle: fewer threads cannot win; look again later
                return
            self._trying = (other, [])
            self.scene.set_threads(other)

    def _decide(self, step):
        other, times = self._trying
        mine = statistics.median(self._times)
        if statistics.median(times) < 0.9 * mine:
            self.current = other
            self.every = self.first
            self.choices.append((step, other))
        else:
            self.every = min(2 * self.every, self.longest)
        self.scene.set_threads(self.current)
        self._trying, self._times, self._steps = None, [], 0
