"""The synthesis' candidate judge with a mark on stderr as each candidate starts (tests/test_design_signals.py): the
Dask workers write to the stderr of the command that started them, so the test reads there that candidates are
being judged on the workers, and the command is waiting for them, before it sends its signal."""

import sys

from wgcad.synthesis.evaluate import evaluate

MARK = "test: a candidate started"


def marked_evaluate(*args, **kwargs):
    print(MARK, file=sys.stderr, flush=True)
    return evaluate(*args, **kwargs)
