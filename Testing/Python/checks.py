"""The tests' checks, one way for every Python test (pvpython or plain python3, no imports).

    check = Checks()                  # Checks(verbose=True) also prints "ok: ..." for each pass
    check(value == 3, "the value is 3 (got %r)" % value)
    check.finish("my test: all checks passed")

A failing check prints "FAILED: what" at once (ctest's FAIL_REGULAR_EXPRESSION then fails the
test whatever its exit status); finish() prints "N check(s) failed" and exits 1 when any failed,
else prints the message and returns. The client/server and web server tests extend finish()
(clientserver.Checks disconnects first; webserver.Checks stops its servers first).
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
