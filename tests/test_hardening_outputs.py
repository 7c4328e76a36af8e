"""Issue 14 regressions on --out (defects 1 and 11): refused before any work, exit 2,
inputs and special files untouched.  Special files are fifos and symlinks in tmp_path:
real /dev files are never touched."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest
from typer.testing import CliRunner

from apdl_like.cli import app as apdl_app
from tests.test_runs_reader import csv_text, warmup
from twin.cli import app
from twin.errors import InputError
from twin.io.atomic import atomic_target, temporary_name, write_text
from twin.io.destinations import check_out_dir, check_out_file


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "pipe.csv"
    os.mkfifo(path)
    return path


def is_fifo(path) -> bool:
    return stat.S_ISFIFO(os.lstat(path).st_mode)


def test_defect1_writer_never_replaces_a_fifo_or_a_symlink_to_one(tmp_path, fifo):
    link = tmp_path / "link.csv"
    link.symlink_to(fifo)
    for target in (fifo, link):
        with pytest.raises(InputError, match="not a regular file"):
            write_text(target, "data")
    assert is_fifo(fifo) and os.path.islink(link)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.csv", "pipe.csv"]


def test_defect1_writer_checks_again_right_before_the_rename(tmp_path):
    target = tmp_path / "late.csv"
    with pytest.raises(InputError, match="not a regular file"), atomic_target(target) as tmp:
        tmp.write_text("data")
        os.mkfifo(target)  # appears while the output is being written
    assert is_fifo(target) and sorted(p.name for p in tmp_path.iterdir()) == ["late.csv"]


def test_defect1_folder_where_a_file_is_expected_and_the_reverse(tmp_path):
    (tmp_path / "dir.msh").mkdir()
    with pytest.raises(InputError, match="is a folder"):
        check_out_file(tmp_path / "dir.msh")
    (tmp_path / "file").write_text("keep")
    with pytest.raises(InputError, match="is a file; a folder is expected"):
        check_out_dir(tmp_path / "file")
    with pytest.raises(InputError, match="is not a folder"):
        check_out_file(tmp_path / "file" / "x.csv")


def test_defect11_out_may_not_be_an_input(tmp_path):
    run = tmp_path / "run.csv"
    run.write_text("x")
    with pytest.raises(InputError, match="also an input"):
        check_out_file(tmp_path / "." / "run.csv", inputs=[run])
    with pytest.raises(InputError, match="also an input"):
        check_out_file(tmp_path / "out.csv", inputs=[run], also=[run])
    (tmp_path / "out" / "run").mkdir(parents=True)
    inside = tmp_path / "out" / "run" / "r.csv"
    inside.write_text("x")
    with pytest.raises(InputError, match="lies where this command writes"):
        check_out_dir(tmp_path / "out", inputs=[inside], owned=["run"])
    check_out_dir(tmp_path / "out", inputs=[inside], owned=["other"])


def test_orphaned_temporary_files_removed_by_the_next_write(tmp_path):
    dead = 2**22 + 4242  # above Linux's default pid_max
    orphan = tmp_path / f".summary.{dead}.0badf00d.json"
    orphan.write_text("half")
    live = tmp_path / temporary_name("summary", ".json")
    live.write_text("being written by this process")
    other = tmp_path / f".report.{dead}.0badf00d.html"
    other.write_text("half, another output")
    write_text(tmp_path / "summary.json", "{}")
    assert not orphan.exists() and live.exists() and other.exists()


def run_cli(application, args):
    result = CliRunner().invoke(application, [str(a) for a in args])
    assert "Traceback" not in result.output
    return result


@pytest.fixture
def run_file(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text(csv_text(warmup()))
    return path


def test_defect11_synth_profile_as_out_refused(tmp_path):
    profile = tmp_path / "p.csv"
    profile.write_text("time_s,speed_rpm\n0,9000\n")
    before = profile.read_bytes()
    result = run_cli(app, ["synth", "--profile", profile, "--minutes", 3, "--ambient", 25,
                           "--seed", 1, "--out", profile])
    assert result.exit_code == 2 and "p.csv" in result.output
    assert profile.read_bytes() == before


def test_defect11_train_run_as_out_refused(run_file):
    before = run_file.read_bytes()
    result = run_cli(app, ["train", run_file, "--out", run_file, "--epochs", 1, "--quiet"])
    assert result.exit_code == 2 and "also an input" in result.output
    assert run_file.read_bytes() == before


@pytest.mark.parametrize("command", [
    ["synth", "--speed", 9000, "--minutes", 3, "--ambient", 25, "--seed", 1, "--out"],
    ["mesh", "--out"],
    ["train", "RUN", "--epochs", 1, "--out"],
    ["snapshot", "RUN", "--time", 100, "--method", "open_loop", "--out"],
])
def test_defect1_file_outputs_refuse_a_fifo(tmp_path, run_file, command):
    suffix = {"synth": ".csv", "mesh": ".msh", "train": ".safetensors", "snapshot": ".png"}
    target = tmp_path / f"pipe{suffix[command[0]]}"
    os.mkfifo(target)
    args = [run_file if a == "RUN" else a for a in command]
    result = run_cli(app, [*args, target])
    assert result.exit_code == 2 and "not a regular file" in result.output
    assert is_fifo(target)


@pytest.mark.parametrize("command", [
    ["replay", "RUN", "--methods", "open_loop", "--out"],
    ["simulate", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--out"],
])
def test_defect6_folder_outputs_refuse_a_file(tmp_path, run_file, command):
    target = tmp_path / "file"
    target.write_text("keep")
    args = [run_file if a == "RUN" else a for a in command]
    result = run_cli(app, [*args, target])
    assert result.exit_code == 2 and "a folder is expected" in result.output
    assert target.read_text() == "keep"


@pytest.mark.parametrize("command, name", [
    (["twin", "simulate", "--speed", 9000, "--minutes", 0.2, "--ambient", 25], "summary.json"),
    (["twin", "simulate", "--speed", 9000, "--minutes", 0.2, "--ambient", 25], "fields.pvd"),
    (["twin", "replay", "RUN", "--methods", "open_loop"], "summary.json"),
    (["twin", "replay", "RUN", "--methods", "open_loop"], "report.html"),
    (["apdl-like", "run", "DECK"], "params.json"),
])
def test_a_folder_where_an_output_file_goes_is_refused_before_any_work(tmp_path, run_file,
                                                                       command, name):
    # simulate unlinked its summary.json first: 'internal error: IsADirectoryError'; replay
    # and apdl-like refused the folder only when writing there, after all the work
    deck = tmp_path / "d.inp"
    deck.write_text("A = 1\n")
    out = tmp_path / "out"
    (out / name).mkdir(parents=True)
    cli = {"twin": app, "apdl-like": apdl_app}[command[0]]
    args = [{"RUN": run_file, "DECK": deck}.get(a, a) for a in command[1:]]
    result = run_cli(cli, [*args, "--out", out])
    assert result.exit_code == 2, result.output
    assert f"{out / name}, option '--out': is a folder, not a file" in result.output
    assert [p.name for p in out.iterdir()] == [name]  # nothing written, nothing removed


def test_defect1_apdl_outputs_refuse_special_files_and_inputs(tmp_path, fifo):
    deck = tmp_path / "d.inp"
    deck.write_text("A = 1\n")
    result = run_cli(apdl_app, ["export-cdb", "--out", fifo])
    assert result.exit_code == 2 and is_fifo(fifo)
    result = run_cli(apdl_app, ["run", deck, "--out", deck])
    assert result.exit_code == 2 and deck.read_text() == "A = 1\n"


def test_apdl_run_leaves_no_result_of_an_earlier_run_beyond_its_own_steps(tmp_path):
    # a 2-step deck then a 1-step deck into one DIR: result_002.vtu stayed, as if the
    # second run had solved two load steps
    steps = ("/PREP7\nET,1,PLANE55\nMP,KXX,1,50\nN,1,0,0\nN,2,1,0\nN,3,1,1\nN,4,0,1\n"
             "E,1,2,3,4\nFINISH\n/SOLU\nANTYPE,STATIC\nD,1,TEMP,20\nD,2,TEMP,20\n"
             "D,3,TEMP,{t}\nD,4,TEMP,{t}\n")
    two = tmp_path / "two.inp"
    two.write_text(steps.format(t=30) + "SOLVE\n" + "D,3,TEMP,40\nD,4,TEMP,40\nSOLVE\n")
    one = tmp_path / "one.inp"
    one.write_text(steps.format(t=50) + "SOLVE\n")
    out = tmp_path / "out"
    (out / "notes").mkdir(parents=True)
    (out / "result_notes.txt").write_text("mine")  # not a result file: kept
    assert run_cli(apdl_app, ["run", two, "--out", out, "--quiet"]).exit_code == 0
    assert (out / "result_002.vtu").exists()
    assert run_cli(apdl_app, ["run", one, "--out", out, "--quiet"]).exit_code == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "log.txt", "notes", "params.json", "result_001.vtu", "result_notes.txt"]


@pytest.mark.parametrize(("command", "suffixes"), [
    (["twin", "synth", "--speed", 9000, "--minutes", 3, "--ambient", 25, "--seed", 1],
     ".csv or .parquet"),
    (["twin", "mesh"], ".msh"),
    (["twin", "train", "RUN", "--epochs", 1], ".safetensors"),
    (["twin", "snapshot", "RUN", "--time", 100, "--method", "open_loop"], ".png"),
    (["twin", "drift", "fit", "RUN", "--target", "disp_z_um"], ".safetensors"),
    (["twin", "drift", "predict", "RUN", "RUN"], ".csv"),
    (["twin", "drift", "select", "RUN", "--target", "disp_z_um"], ".json"),
    (["apdl-like", "export-cdb"], ".cdb"),
])
@pytest.mark.parametrize("name", ["out.txt", "out", "out.msh.bak"])
def test_an_output_file_of_another_suffix_is_refused_before_any_work(tmp_path, run_file,
                                                                    command, suffixes, name):
    # each command checked the suffix in its own words, after other work (train, snapshot),
    # without naming the option (mesh), not at all (export-cdb wrote any name as CDB) or
    # case-sensitively (mesh refused OUT.MSH, which the others take)
    before = run_file.read_bytes()
    out = tmp_path / name
    cli = {"twin": app, "apdl-like": apdl_app}[command[0]]
    args = [run_file if a == "RUN" else a for a in command[1:]]
    result = run_cli(cli, [*args, "--out", out])
    assert result.exit_code == 2, result.output
    assert result.output == f"error: {out}, option '--out': must end in {suffixes}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]
    assert run_file.read_bytes() == before


def test_an_output_suffix_is_checked_in_any_case(tmp_path):
    out = tmp_path / "MESH.MSH"
    with pytest.raises(InputError, match="must end in .png"):
        check_out_file(out, suffixes=(".png",))
    assert check_out_file(out, suffixes=(".msh",)) == out


def _unwritable_folders(tmp_path):
    """Folders the test's user may not write in: a read-only folder (root writes there
    anyway) and /proc, which refuses root too."""
    folders = []
    if os.geteuid() != 0:
        locked = tmp_path / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        folders.append(locked)
    if os.path.isdir("/proc/self"):
        folders.append(Path("/proc"))
    if not folders:
        pytest.skip("no folder here that the test's user may not write in")
    return folders


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="no /proc here")
def test_an_out_on_proc_is_told_as_the_kernels_files_not_as_missing():
    # '--out /proc/x' said "cannot write in /proc: No such file or directory" of a folder
    # that is there: the system's word for a file system that makes no files
    result = run_cli(app, ["mesh", "--quiet", "--out", "/proc/x.msh"])
    assert result.exit_code == 2
    assert result.output == ("error: /proc/x.msh, option '--out': cannot write in /proc: the "
                             "kernel's proc file system, which holds no files a command can "
                             "write (choose a folder on a disk)\n")


def test_file_system_type_reads_the_innermost_mount():
    from twin.io.destinations import file_system_type

    mountinfo = ("22 27 0:21 / /proc rw,relatime - proc proc rw\n"
                 "27 1 8:1 / / rw,relatime shared:1 - ext4 /dev/sda1 rw\n"
                 "30 27 0:40 / /mnt/my\\040disk rw master:2 - vfat /dev/sdb1 rw\n"
                 "31 30 0:41 / /mnt/my\\040disk rw - tmpfs tmpfs rw\n")
    assert file_system_type(Path("/proc/sys"), mountinfo) == "proc"
    assert file_system_type(Path("/procx"), mountinfo) == "ext4"  # not under /proc
    assert file_system_type(Path("/mnt/my disk/a"), mountinfo) == "tmpfs"  # stacked: last
    assert file_system_type(Path("/mnt/my"), mountinfo) == "ext4"
    assert file_system_type(Path("/x"), "") is None


@pytest.mark.parametrize(("command", "name"), [
    (["twin", "synth", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--seed", 1,
      "--quiet"], "new/run.csv"),
    (["twin", "mesh", "--quiet"], "m.msh"),
    (["twin", "replay", "RUN", "--methods", "open_loop", "--quiet"], "new"),
    (["twin", "simulate", "--speed", 9000, "--minutes", 0.2, "--ambient", 25, "--quiet"], ""),
    (["twin", "drift", "select", "RUN", "--target", "disp_z_um"], "ranking.json"),
    (["apdl-like", "run", "DECK", "--quiet"], "out"),
])
def test_an_unwritable_out_is_refused_before_any_work(tmp_path, run_file, command, name):
    # the write failed after all the work: 'internal error: PermissionError', exit 1
    deck = tmp_path / "d.inp"
    deck.write_text("A = 1\n")
    cli = {"twin": app, "apdl-like": apdl_app}[command[0]]
    args = [{"RUN": run_file, "DECK": deck}.get(a, a) for a in command[1:]]
    for folder in _unwritable_folders(tmp_path):
        out = folder / name if name else folder
        result = run_cli(cli, [*args, "--out", out])
        assert result.exit_code == 2, result.output
        assert result.output.startswith(f"error: {out}, option '--out': cannot write in "
                                        f"{folder}: "), result.output
        assert "\n" not in result.output.rstrip("\n")
        if name:
            assert not (folder / name.split("/")[0]).exists()


@pytest.mark.parametrize("command", [
    ["synth", "--speed", 9000, "--minutes", 2, "--ambient", 25, "--seed", 1],
    ["train", "RUN", "--epochs", 1],
])
@pytest.mark.parametrize("out", ["", "/"])
def test_an_out_without_a_file_name_is_bad_input(tmp_path, run_file, monkeypatch, command,
                                                 out):
    # '--out ""' (an unset shell variable) is the folder '.': the name of the file written
    # beside it (RUN.truth.csv, MODEL.report.json) was an internal error
    monkeypatch.chdir(tmp_path)
    args = [run_file if a == "RUN" else a for a in command]
    result = run_cli(app, [*args, "--out", out])
    assert result.exit_code == 2, result.output
    assert result.output.startswith(f"error: {out or '.'}, option '--out': ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_a_symlink_loop_given_as_a_run_is_bad_input(tmp_path, run_file):
    # pathlib's resolve() raised RuntimeError on the loop in the --out check: exit 1
    (tmp_path / "a.csv").symlink_to(tmp_path / "b.csv")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    out = tmp_path / "out"
    result = run_cli(app, ["replay", tmp_path / "a.csv", run_file, "--methods", "open_loop",
                           "--snapshots", "none", "--quiet", "--out", out])
    assert result.exit_code == 2, result.output
    assert result.output == (f"error: {tmp_path / 'a.csv'}: cannot read file: Too many "
                             "levels of symbolic links\n")
    assert sorted(p.name for p in out.iterdir()) == ["report.html", "run", "summary.json"]


def test_a_symlink_loop_given_to_train_is_bad_input(tmp_path, run_file):
    (tmp_path / "a.csv").symlink_to(tmp_path / "b.csv")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    result = run_cli(app, ["train", tmp_path / "a.csv", run_file, "--epochs", 1, "--quiet",
                           "--out", tmp_path / "m.safetensors"])
    assert result.exit_code == 2, result.output
    assert result.output == (f"error: {tmp_path / 'a.csv'}: cannot read file: Too many "
                             "levels of symbolic links\n")
    assert not (tmp_path / "m.safetensors").exists()
