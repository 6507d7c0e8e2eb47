"""Runs one command as a child under a time and memory cap; writes its peak RSS and exit status as JSON.

usage: python3 -I -S launch.py REPORT.json TIMEOUT_SECONDS MEMORY_LIMIT_BYTES -- COMMAND [ARGS...]

Why a separate launcher: at exec, Linux folds the peak RSS of the process that spawned a child into the
child's ru_maxrss, so a child of the benchmark runner (which holds numpy and result arrays) would report
at least the runner's peak. This launcher imports only built-in modules, so the peak it passes on is a few
MB, and ru_maxrss is the larger of that and the child's own peak. MEMORY_LIMIT_BYTES (0: none) caps the
child's address space with RLIMIT_AS; on timeout the child is killed with SIGKILL.
"""

import json
import os
import resource
import signal
import sys
import time


def main() -> int:
    report_path, timeout_seconds, memory_limit = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    if sys.argv[4] != "--" or len(sys.argv) < 6:
        print(__doc__, file=sys.stderr)
        return 2
    command = sys.argv[5:]

    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        try:
            if memory_limit > 0:
                resource.setrlimit(resource.RLIMIT_AS, (memory_limit, memory_limit))
            os.execvp(command[0], command)
        except OSError as error:
            print(f"launch.py: cannot run {command[0]}: {error}", file=sys.stderr)
        os._exit(127)

    timed_out = False

    def kill_child(signum, frame):
        nonlocal timed_out
        timed_out = True
        os.kill(pid, signal.SIGKILL)

    signal.signal(signal.SIGALRM, kill_child)
    signal.setitimer(signal.ITIMER_REAL, timeout_seconds)
    _, status, usage = os.wait4(pid, 0)
    signal.setitimer(signal.ITIMER_REAL, 0)
    wall_seconds = time.perf_counter() - start

    report = {
        "exit_code": os.WEXITSTATUS(status) if os.WIFEXITED(status) else None,
        "signal": os.WTERMSIG(status) if os.WIFSIGNALED(status) else None,
        "timed_out": timed_out,
        "peak_rss_bytes": usage.ru_maxrss * 1024,
        "wall_seconds": wall_seconds,
        "user_seconds": usage.ru_utime,
        "system_seconds": usage.ru_stime,
    }
    with open(report_path, "w") as file:
        json.dump(report, file)
    return 0


if __name__ == "__main__":
    sys.exit(main())
