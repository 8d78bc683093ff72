"""Progress reports of a run: the record a callback receives, and the bar shown for
progress=True (tqdm when it is installed, else a line on stderr every second)."""
import collections
import sys
import time

from .errors import ArgumentError

Progress = collections.namedtuple("Progress", "stage channel n_channels done total")
Progress.__doc__ = """One progress report. `stage` is "prepare" (objects whose back-side
sources are set up, once per run before the first channel's photons, where a deviation map
needs them), "photons" (done/total photons of the channel), "render" (rows of a sensor) or
"output" (0/1, then 1/1) or "read" (load_photon_map: a channel's stored photons in the
file, 0 before its records are read and all once its map is built); `channel` is the
0-based index of the channel among `n_channels`. In `bands` the stage is "bands": `channel` is the render (the nominal one,
then the nuisances'; `n_channels` the renders, 0 while the nominal one runs and their
count is not known yet) and done/total its candidate channels. In `load_sequence` it is
"frames": done/total frames checked (channel and n_channels 0)."""

_UNITS = {"prepare": "objects", "photons": "photons", "render": "rows", "output": "steps",
          "bands": "channels", "read": "photons", "frames": "frames"}


class _Bar:
    """A progress display: one tqdm bar per stage and channel, and a new one where a
    report counts from the start again (the next pass of a run that adds passes), so that
    no bar runs backwards."""

    def __init__(self):
        try:
            import tqdm
            self._tqdm = tqdm.tqdm
        except ImportError:
            self._tqdm = None
        self._key = None
        self._bar = None
        self._last_line = 0.0

    def __call__(self, p):
        key = (p.stage, p.channel)
        if p.stage == "bands":
            of = f"/{p.n_channels}" if p.n_channels else " (nominal)"
            label = f"bands: render {p.channel + 1}{of}"
        else:
            label = f"channel {p.channel + 1}/{p.n_channels} {p.stage}"
        if self._tqdm is not None:
            if key != self._key or p.done < self._bar.n or p.total != self._bar.total:
                self.close()
                self._key = key
                self._bar = self._tqdm(total=p.total, desc=label, unit=_UNITS.get(p.stage, ""),
                                       unit_scale=p.stage == "photons", leave=False)
            self._bar.update(p.done - self._bar.n)
        else:
            now = time.monotonic()
            if now - self._last_line >= 1.0 or p.done == p.total:
                self._last_line = now
                print(f"thzmap: {label}: {p.done}/{p.total} {_UNITS.get(p.stage, '')}",
                      file=sys.stderr, flush=True)
        return False

    def close(self):
        if self._bar is not None:
            self._bar.close()
        self._bar = None
        self._key = None


class _Callback:
    def __init__(self, fn):
        self._fn = fn

    def __call__(self, p):
        return bool(self._fn(p))


def check(progress):
    """ArgumentError unless progress is None, False, True or a callable."""
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise ArgumentError(f"progress: expected None, True or a callable, got {progress!r}")


def make_reporter(progress, bar=None):
    """None/False: no reports; True: a bar (`bar()`, default a run's _Bar); a callable:
    called with each report, a true return value cancels the run."""
    check(progress)
    if progress is None or progress is False:
        return None
    if progress is True:
        return bar() if bar is not None else _Bar()
    return _Callback(progress)
