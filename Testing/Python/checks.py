"""The tests' checks, one way for every Python test (pvpython or plain python3, no imports).

    check = Checks()                  # Checks(verbose=True) also prints "ok: ..." for each pass
    check(value == 3, "the value is 3 (got %r)" % value)
    check.finish("my test: all checks passed")

A failing check prints "FAILED: what" at once (ctest's FAIL_REGULAR_EXPRESSION then fails the
test whatever its exit status); finish() prints "N check(s) failed" and exits 1 when any failed,
else prints the message and returns. The client/server and web server tests extend finish()
(clientserver.Checks disconnects first; webserver.Checks stops its servers first).

    result, text = captured(lambda: reader.UpdatePipeline())   # pvpython only

captured() runs a step that must emit a known VTK error or warning with them captured instead of
printed, so that the test checks the text instead of failing on it (FAIL_REGULAR_EXPRESSION).
"""
import sys


class Checks:
    def __init__(self, verbose=False):
        self.failures = []
        self.verbose = verbose

    def __call__(self, ok, what):
        """Records one check; returns ok, so a test can go on only when it passed."""
        if not ok:
            self.failures.append(what)
            print("FAILED: " + what, flush=True)
        elif self.verbose:
            print("ok: " + what, flush=True)
        return ok

    def finish(self, passed_message, exit=sys.exit):
        """Exit status 1 when a check failed; otherwise says passed_message."""
        if self.failures:
            print("%d check(s) failed" % len(self.failures))
            sys.stdout.flush()
            exit(1)
        print(passed_message)
        sys.stdout.flush()


def captured(function):
    """Run function with VTK errors and warnings captured instead of printed.

    Returns (result, captured text). Used only around a step that must emit a
    known message, so that the test checks it instead of failing on it. VTK's
    errors reach both the output window and the logger's stderr sink: both are
    redirected, and given back afterwards whatever the step raised.
    """
    # Imported here, so that plain python3 tests import this module without VTK.
    from vtkmodules.vtkCommonCore import vtkLogger, vtkOutputWindow, vtkStringOutputWindow

    capture = vtkStringOutputWindow()
    previous = vtkOutputWindow.GetInstance()
    verbosity = vtkLogger.GetCurrentVerbosityCutoff()
    vtkOutputWindow.SetInstance(capture)
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    try:
        result = function()
    finally:
        vtkOutputWindow.SetInstance(previous)
        vtkLogger.SetStderrVerbosity(verbosity)
    return result, capture.GetOutput()
