"""A command stopped from outside stops cleanly: SIGINT (Ctrl-C, which a terminal sends to the
whole process group) and SIGTERM (``timeout``, ``docker stop``, a batch scheduler's cancel) end
``fit``, ``fit-many``, ``compare`` and ``design`` within seconds, with one ``interrupted:`` line
and no traceback, exit status 130 / 143, existing output files as they were, and no process of
the command left (pool workers and multiprocessing's resource tracker included; on a Dask
cluster, the command's tasks are gone and the cluster stays).

Each command runs as ``python -m identification`` in a session of its own, so that its process
group is exactly the command and what it started."""
import json
import os
import signal
import subprocess
import sys
import time

import psutil
import pytest

from conftest import DATA, REPO, paper_parameters

SINE = DATA / "synthetic_table5_sine_2mm_10Hz.csv"
EXIT_S = 10.0          # the command must be gone this long after the signal
LINGER_S = 5.0         # and every process of its group this long after that
START_S = 60.0         # generous: imports and worker start on a loaded 2-core machine
EXIT_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143}


class Command:
    """``python -m identification ARGS`` in its own session; stdout and stderr go to files (a
    pipe would be held open by any process left behind, and hide that the command ended)."""

    def __init__(self, arguments, folder):
        self.stdout_path, self.stderr_path = folder / "stdout.txt", folder / "stderr.txt"
        with open(self.stdout_path, "wb") as out, open(self.stderr_path, "wb") as err:
            self.process = subprocess.Popen([sys.executable, "-m", "identification", *map(str, arguments)], cwd=REPO,
                                            stdout=out, stderr=err, start_new_session=True)
        self.group = self.process.pid      # the session leader's pid is its process group's id
        self.started = time.monotonic()

    @property
    def stderr(self) -> str:
        return self.stderr_path.read_text()

    @property
    def stdout(self) -> str:
        return self.stdout_path.read_text()

    def group_processes(self) -> list[psutil.Process]:
        """The live processes of the command's group, the command itself included (zombies,
        which hold neither memory nor files, left out)."""
        found = []
        for process in psutil.process_iter(["status"]):
            try:
                if os.getpgid(process.pid) == self.group and process.info["status"] != psutil.STATUS_ZOMBIE:
                    found.append(process)
            except (ProcessLookupError, psutil.Error):
                pass
        return found

    def wait_until(self, condition, what: str):
        while not condition():
            assert self.process.poll() is None, f"the command ended before {what}:\n{self.stderr}"
            assert time.monotonic() - self.started < START_S, f"no {what} after {START_S} s:\n{self.stderr}"
            time.sleep(0.1)

    def wait_until_running(self, workers: int = 0):
        """Until the command runs (its SIGTERM handler is installed: Python has imported
        everything and ``main`` has begun) and, with ``workers``, its pool's worker processes
        and resource tracker exist."""
        def handles_sigterm():
            status = open(f"/proc/{self.process.pid}/status").read()
            caught = int(next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), 16)
            return bool(caught & (1 << (signal.SIGTERM - 1)))    # bit n-1: signal n
        self.wait_until(handles_sigterm, "SIGTERM handler")
        if workers:
            self.wait_until(lambda: len(self.group_processes()) >= 1 + workers + 1, f"{workers} pool workers")

    def stop(self, signal_number, whole_group: bool):
        """Send the signal (to the group, as a terminal's Ctrl-C does, or to the command only, as
        ``timeout`` and ``docker stop`` do), then wait for the command and its group to end."""
        if whole_group:
            os.killpg(self.group, signal_number)
        else:
            self.process.send_signal(signal_number)
        sent = time.monotonic()
        try:
            self.status = self.process.wait(timeout=EXIT_S)
        except subprocess.TimeoutExpired:
            self.status = None
        self.seconds = time.monotonic() - sent
        ended = time.monotonic()
        while self.group_processes() and time.monotonic() - ended < LINGER_S:
            time.sleep(0.2)
        self.left_behind = [(p.pid, " ".join(p.cmdline())[:120]) for p in self.group_processes()]

    def kill_group(self):
        """Whatever a failed test left running."""
        for process in self.group_processes():
            process.kill()


@pytest.fixture
def command(tmp_path):
    started = []

    def start(*arguments):
        started.append(Command(arguments, tmp_path))
        return started[-1]
    yield start
    for one in started:
        one.kill_group()


def assert_stopped_cleanly(run: Command, signal_number, message: str = "interrupted: nothing written"):
    assert run.status is not None, f"still running {EXIT_S} s after the signal:\n{run.stderr}"
    assert run.status == EXIT_STATUS[signal_number], run.stderr
    assert run.seconds < EXIT_S
    assert "Traceback" not in run.stderr and "KeyboardInterrupt" not in run.stderr, run.stderr
    interrupted = [line for line in run.stderr.splitlines() if line.startswith("interrupted")]
    assert interrupted == [message], run.stderr
    assert run.stderr.splitlines()[-1] == message
    assert run.left_behind == [], f"left running: {run.left_behind}"


@pytest.mark.slow
def test_sigterm_to_fit_ends_it_with_its_pool_and_leaves_the_output_file(tmp_path, command):
    # The signal goes to the command only, as `timeout` and `docker stop` send it: the workers
    # and the resource tracker must be ended by the command. A short screening, so that the
    # signal comes during the least-squares stages, whose tasks take seconds: a command that
    # waited for its running tasks would not end in time.
    out = tmp_path / "fit.json"
    out.write_bytes(b'{"previous": "fit"}\n')
    run = command("fit", "--sine", SINE, "--out", out, "--workers", "2", "--screening", "64")
    run.wait_until_running(workers=2)
    time.sleep(3.0)
    run.stop(signal.SIGTERM, whole_group=False)
    assert_stopped_cleanly(run, signal.SIGTERM)
    assert out.read_bytes() == b'{"previous": "fit"}\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fit.json", "stderr.txt", "stdout.txt"]


@pytest.mark.slow
def test_ctrl_c_to_fit_many_keeps_the_finished_bushing_and_names_it(tmp_path, command):
    # A Kelvin-Voigt bushing (linear least squares) finishes in seconds, the other would take
    # minutes. Ctrl-C reaches every process of the group: the worker that fitted the quick one
    # waits for work (in Python, where a SIGINT not ignored would be a KeyboardInterrupt and its
    # traceback), the other one fits.
    fleet, out = tmp_path / "fleet", tmp_path / "out"
    for name, model in (("a_quick", "kelvin_voigt"), ("b_slow", "proposed")):
        (fleet / name).mkdir(parents=True)
        (fleet / name / "tests.json").write_text(json.dumps({"sine": [str(SINE)], "model": model}))
    out.mkdir()
    (out / "summary.csv").write_text("an earlier run's summary\n")
    (out / "b_slow.json").write_text("an earlier run's fit\n")
    run = command("fit-many", fleet, "--out", out, "--workers", "2")
    run.wait_until(lambda: (out / "a_quick.json").exists(), "file of the quick bushing")
    run.stop(signal.SIGINT, whole_group=True)
    assert_stopped_cleanly(run, signal.SIGINT, f"interrupted: wrote {out / 'a_quick.json'}; nothing else written")
    assert json.loads((out / "a_quick.json").read_text())["model"] == "KelvinVoigtBushing"
    assert (out / "summary.csv").read_text() == "an earlier run's summary\n"
    assert (out / "b_slow.json").read_text() == "an earlier run's fit\n"
    assert sorted(p.name for p in out.iterdir()) == ["a_quick.json", "b_slow.json", "summary.csv"]


@pytest.mark.slow
def test_sigterm_to_design_ends_it_without_output(tmp_path, command):
    from fmu_src.parameter_files import save_ensemble
    base = paper_parameters("table2")
    # 200 members: the ranking takes half a minute, far longer than the wait below
    members = [dict(base, A2=base["A2"] * (1.0 + 0.001 * i)) for i in range(200)]
    save_ensemble(tmp_path / "ensemble.json", members, provenance={"tests": [{"noise_N": 10.0}]})
    run = command("design", "--ensemble", tmp_path / "ensemble.json")
    run.wait_until_running()
    time.sleep(1.5)
    run.stop(signal.SIGTERM, whole_group=True)
    assert_stopped_cleanly(run, signal.SIGTERM)
    assert run.stdout == ""


@pytest.mark.slow
def test_ctrl_c_to_compare_on_a_dask_cluster_cancels_its_tasks_and_leaves_the_cluster(tmp_path, command):
    pytest.importorskip("distributed", reason="the Dask engine needs distributed (the 'dask' extra)")
    import logging
    from dask.distributed import Client, LocalCluster
    out = tmp_path / "compare"
    out.mkdir()
    (out / "comparison.csv").write_text("an earlier comparison\n")

    def command_tasks(dask_scheduler):
        return len(dask_scheduler.tasks)

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.CRITICAL + 1) as cluster, Client(cluster) as client:
        workers = set(client.nthreads())
        # small screening tasks: a cancelled task that is running goes on to its end (a worker's
        # thread cannot be stopped), and the cluster's close at the end of the test waits for it
        run = command("compare", "--sine", SINE, "--models", "proposed,spencer", "--screening", "512", "--out", out,
                      "--scheduler", cluster.scheduler_address)
        run.wait_until_running()
        run.wait_until(lambda: client.run_on_scheduler(command_tasks) > 0, "task on the cluster")
        run.stop(signal.SIGINT, whole_group=True)
        assert_stopped_cleanly(run, signal.SIGINT)
        deadline = time.monotonic() + LINGER_S
        while client.run_on_scheduler(command_tasks) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert client.run_on_scheduler(command_tasks) == 0          # cancelled and forgotten
        assert set(client.nthreads()) == workers                     # the cluster is untouched
        assert client.submit(sum, [1, 2]).result(timeout=30) == 3
    assert (out / "comparison.csv").read_text() == "an earlier comparison\n"
    assert sorted(p.name for p in out.iterdir()) == ["comparison.csv"]


def test_a_file_being_written_is_finished_before_the_signal_is_raised(tmp_path):
    """In-process: the signal arrives while a file is written; the file is completed and put
    in place whole, then the interruption is raised, naming it."""
    from identification.interrupt import Interrupted, interrupted_message, signals_raise, writing
    target = tmp_path / "result.json"
    target.write_text("old\n")
    with pytest.raises(Interrupted) as stopped:
        with signals_raise():
            with writing(target) as temporary:
                with open(temporary, "w") as stream:
                    stream.write("new, ")
                    os.kill(os.getpid(), signal.SIGTERM)
                    time.sleep(0.05)           # the handler has run by now: it must not raise here
                    stream.write("complete\n")
                assert target.read_text() == "old\n"
            pytest.fail("the interruption must be raised when the file is written")
    assert stopped.value.exit_status == 143
    assert target.read_text() == "new, complete\n"
    assert interrupted_message() == f"interrupted: wrote {target}; nothing else written"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.json"]


def test_a_write_that_fails_leaves_the_earlier_file_and_no_partial_one(tmp_path):
    from identification.interrupt import writing
    target = tmp_path / "result.csv"
    target.write_text("old\n")
    with pytest.raises(ValueError):
        with writing(target) as temporary:
            temporary.write_text("half")
            raise ValueError("the writer failed")
    assert target.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.csv"]


def test_ctrl_c_while_the_command_still_imports_ends_it_with_the_one_line(tmp_path, command):
    # Between the package's first line and cli.main (a second or two of imports) only the early
    # handler stands between Ctrl-C and a traceback from the middle of an import. The window is
    # told from outside: numpy is loaded (the package's imports are under way) and the SIGTERM
    # handler of cli.main is not yet installed.
    run = command("fit", "--sine", SINE, "--out", tmp_path / "fit.json")

    def importing():
        status = open(f"/proc/{run.process.pid}/status").read()
        caught = int(next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), 16)
        assert not caught & (1 << (signal.SIGTERM - 1)), "the command reached main before the test saw it import"
        return "numpy" in open(f"/proc/{run.process.pid}/maps").read()
    run.wait_until(importing, "numpy being imported")
    run.stop(signal.SIGINT, whole_group=True)
    assert_stopped_cleanly(run, signal.SIGINT)
    assert not (tmp_path / "fit.json").exists()


def test_the_early_handler_is_only_the_command_lines():
    # A program that imports the package keeps Python's Ctrl-C (KeyboardInterrupt where it is).
    script = ("import signal, identification; "
              "print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)")
    # the child starts with Ctrl-C at its default even where the suite runs with it ignored (a
    # shell's background job): Python installs its handler only where SIGINT is not ignored
    output = subprocess.run([sys.executable, "-c", script], cwd=REPO, capture_output=True, text=True, check=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert output.stdout.strip() == "True"


def test_a_signal_inside_compiled_code_is_the_same_stop(monkeypatch, capsys, tmp_path):
    """A signal that lands while numba loads its cache reaches the command as a SystemError whose
    cause is our Interrupted: one line and 143, as any SIGTERM, not a traceback."""
    from identification.cli import arguments as cli
    from identification.interrupt import Interrupted

    def compiled_call_interrupted(args):
        try:
            raise Interrupted(signal.SIGTERM)
        except Interrupted as stop:
            raise SystemError("CPUDispatcher(<function _population_loop>) returned a result with an exception set") \
                from stop
    monkeypatch.setitem(cli.COMMANDS, "design", compiled_call_interrupted)
    assert cli.main(["design", "--ensemble", str(tmp_path / "e.json")]) == 128 + signal.SIGTERM
    assert capsys.readouterr().err.splitlines()[-1].startswith("interrupted")

    def other_system_error(args):
        raise SystemError("a real one")
    monkeypatch.setitem(cli.COMMANDS, "design", other_system_error)
    with pytest.raises(SystemError, match="a real one"):
        cli.main(["design", "--ensemble", str(tmp_path / "e.json")])


def test_compare_stopped_after_its_third_fit_leaves_those_three_models_files(monkeypatch, capsys, tmp_path):
    """compare writes each model's parameter file and its row as the model is settled: a SIGTERM
    raised after the third fit (Kelvin-Voigt, then two searched models) leaves their three
    files and comparison.csv with their three rows, and the one line names them."""
    import csv

    from identification.cli import arguments as cli
    from identification.fitting.search import Search
    from identification.interrupt import Interrupted

    finished = []
    finish = Search.finish

    def finish_then_stop(self, *args, **kwargs):
        result = finish(self, *args, **kwargs)
        finished.append(result.model)
        if len(finished) == 3:              # the fourth fit: the signal arrives while it runs
            raise Interrupted(signal.SIGTERM)
        return result
    monkeypatch.setattr(Search, "finish", finish_then_stop)
    out = tmp_path / "compare"
    code = cli.main(["compare", "--sine", str(SINE), "--models", "kelvin_voigt,single_bouc_wen,spencer,berg",
                     "--no-race", "--screening", "32", "--starts", "2", "--no-ensemble", "--quiet", "--workers", "1",
                     "--out", str(out)])
    assert code == 128 + signal.SIGTERM
    settled = ["kelvin_voigt", *finished[:2]]
    written = sorted(p.name for p in out.iterdir())
    assert written == sorted(["comparison.csv", *(f"params_{model}.json" for model in settled)])
    for model in settled:
        assert json.loads((out / f"params_{model}.json").read_text())["parameters"]
    with open(out / "comparison.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert [row["model"] for row in rows] == settled and all(row["recommended"] == "" for row in rows)
    (line,) = [line for line in capsys.readouterr().err.splitlines() if line.startswith("interrupted")]
    assert line.startswith("interrupted: wrote") and all(f"params_{model}.json" in line for model in settled)
    assert line.count("comparison.csv") == 1        # written again as each model settled, named once
