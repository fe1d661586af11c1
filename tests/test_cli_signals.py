"""The command line while it runs: Ctrl-C is one line and exit 130, progress goes to stderr only.

Each command runs in a real subprocess (``python -m lindstedt``).  Ctrl-C is a SIGINT sent once the
process has used a given CPU time (read from /proc, so a loaded machine only delays it): 0.15 s is
inside the command's imports (numpy, scipy, sympy), 1.5 s inside its computation.  The progress is
read through a pseudo-terminal (the terminal case) and through pipes (the summary line).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from lindstedt.cli import main

pytestmark = pytest.mark.skipif(not Path("/proc/self/stat").exists() or sys.platform == "win32",
                                reason="needs Linux /proc (CPU time of a child) and POSIX signals")

#: a hang guard only (the commands below take seconds); never a timing assertion
HANG = 300.0

README_SWEEP = ["forced", "Max(0, u - 1/5)", "--eps", "1", "--zeta", "0.02", "--forcing", "0.04", "--from", "0.8", "--to", "1.6"]
#: minutes of continuation (a lightly damped Duffing over a wide range): always interrupted mid-way
LONG_SWEEP = ["forced", "u**3", "--eps", "1", "--zeta", "0.001", "--forcing", "1", "--from", "0.5", "--to", "20"]
LONG_EXPAND = ["expand", "Max(0, u - 1/3)", "--order", "30", "--a0", "1", "--omega0", "1"]


def _cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")  # utime + stime


def _interrupt_after(argv: list[str], cpu: float) -> subprocess.CompletedProcess:
    process = subprocess.Popen([sys.executable, "-m", "lindstedt", *argv], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + HANG
    try:
        while _cpu_seconds(process.pid) < cpu:
            assert process.poll() is None, f"{argv} ended before {cpu} s of CPU: choose a longer command"
            assert time.monotonic() < deadline, "hang"
            time.sleep(0.01)
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=HANG)
    finally:
        process.kill()
    return subprocess.CompletedProcess(argv, process.returncode, out, err)


@pytest.mark.parametrize("argv, cpu", [
    (LONG_SWEEP, 0.15),   # while importing
    (LONG_SWEEP, 1.5),    # while continuing
    (README_SWEEP, 0.3),
    (LONG_EXPAND, 1.5),   # while deriving order after order
])
def test_ctrl_c_prints_one_line_and_exits_130(argv, cpu):
    result = _interrupt_after(argv, cpu)
    assert result.stderr == "error: interrupted\n", result.stderr
    assert result.returncode == 130 and result.stdout == ""


def _on_a_terminal(argv: list[str], columns: int = 100) -> tuple[int, str, str]:
    """(status, stdout, stderr) with stderr a pseudo-terminal of ``columns`` columns and stdout a pipe."""
    import fcntl
    import pty
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    process = subprocess.Popen([sys.executable, "-m", "lindstedt", *argv], stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    chunks: list[bytes] = []

    def drain() -> None:  # read while it runs: Linux drops what is left once the terminal's last writer exits
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:
                return
            if not chunk:
                return
            chunks.append(chunk)

    reader = threading.Thread(target=drain)
    reader.start()
    try:
        out = process.communicate(timeout=HANG)[0]
    finally:
        process.kill()
        reader.join()
        os.close(master)
    return process.returncode, out.decode(), b"".join(chunks).decode()


def test_a_sweep_shows_its_progress_on_a_terminal_and_keeps_stdout_clean():
    pytest.importorskip("tqdm", reason="the bar is tqdm's (optional: pip install tqdm)")
    status, out, err = _on_a_terminal([*README_SWEEP, "--format", "json"])
    data = json.loads(out)
    assert status == 0 and data["success"] is True
    counts = [int(n) for n in re.findall(r"\rforced: (\d+) points", err)]  # tqdm redraws at most every 0.1 s
    assert counts and counts == sorted(counts) and counts[-1] <= len(data["points"])  # a tick a point
    assert "Ω = " in err and "max|u| = " in err  # the bar says where the branch is
    assert err.endswith("\r") and not err.strip("\r ").endswith("s\n")  # cleared at the end, no summary line


def test_a_high_order_expansion_shows_its_orders_on_a_terminal():
    pytest.importorskip("tqdm", reason="the bar is tqdm's (optional: pip install tqdm)")
    status, out, err = _on_a_terminal(["expand", "Max(0, u - 1/3)", "--order", "10", "--a0", "1", "--omega0", "1",
                                       "--format", "json"])
    assert status == 0 and json.loads(out)["order"] == 10
    done = [int(n) for n in re.findall(r"\rexpand: .*?(\d+)/12 ", err)]  # orders 0-10, then the output
    assert done and done == sorted(done) and "order " in err and err.endswith("\r")


def test_without_a_terminal_a_long_command_prints_one_summary_line():
    result = subprocess.run([sys.executable, "-m", "lindstedt", *README_SWEEP, "--format", "json"], capture_output=True,
                            text=True, timeout=HANG, check=False)
    data = json.loads(result.stdout)
    assert result.returncode == 0 and data["success"] is True
    match = re.fullmatch(r"forced: (\d+) points, 2 folds, \d+\.\d s\n", result.stderr)
    assert match and int(match[1]) == len(data["points"]), result.stderr
    assert [b["kind"] for b in data["bifurcations"]] == ["fold", "fold"]


@pytest.mark.slow  # three CLI runs, one a high order (9 s)
def test_summaries_of_nnm_shooting_and_high_orders_and_silence_below(capsys):
    chain = str(Path(__file__).resolve().parents[1] / "examples" / "chain2.json")
    assert main(["nnm", chain, "--mode", "1", "--numeric", "--energy", "1", "--eps", "1", "--format", "json"]) == 0
    captured = capsys.readouterr()
    data = json.loads(captured.out)
    assert re.fullmatch(rf"nnm: mode 1 by shooting, {data['newton_iterations']} Newton iterations, "
                        rf"{data['flow_evaluations']} flows, \d+\.\d s\n", captured.err), captured.err
    assert main(["expand", "u**3", "--order", "10", "--format", "json"]) == 0
    assert re.fullmatch(r"expand: orders 0-10, \d+\.\d s\n", capsys.readouterr().err)
    assert main(["expand", "u**3", "--order", "9", "--format", "json"]) == 0
    assert capsys.readouterr().err == ""  # short commands print their result only
    # a low order priced above a second (a gap with symbolic a0 and omega0: ~2 s) reports too
    assert main(["expand", "Max(0, u - 1/3)", "--order", "4", "--format", "json"]) == 0
    assert re.fullmatch(r"expand: orders 0-4, \d+\.\d s\n", capsys.readouterr().err)
    assert main(["forced", "u**3", "--eps", "0.1", "--zeta", "0.05", "--at", "1.05"]) == 0
    assert capsys.readouterr().err == ""


def test_a_failed_run_prints_its_error_line_not_a_summary(tmp_path, capsys):
    system = tmp_path / "system.json"
    system.write_text(json.dumps({"M": [[1, 0], [0, 1]], "K": [[2, -1], [-1, 2]], "A": [[1, 0]], "b": [0]}))
    assert main(["nnm", str(system), "--mode", "1", "--numeric", "--energy", "-1", "--eps", "0.1"]) == 1
    assert capsys.readouterr().err == "error: the computation did not succeed (see its message above)\n"
