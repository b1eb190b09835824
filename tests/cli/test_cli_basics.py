from mechsyn import __version__
from mechsyn.cli.main import main


def test_version(capsys):
    assert main(["version"]) == 0
    assert __version__ in capsys.readouterr().out


def test_unknown_command_is_usage_error(capsys):
    assert main(["no-such-command"]) == 2


def test_write_atomic_gives_ordinary_permissions(tmp_path):
    import os
    import stat

    from mechsyn.results import write_atomic

    mask = os.umask(0o022)
    try:
        write_atomic(tmp_path / "a.txt", "x")
    finally:
        os.umask(mask)
    assert stat.S_IMODE(os.stat(tmp_path / "a.txt").st_mode) == 0o644


def test_error_text_in_brackets_is_shown(run_cli, tmp_path):
    p = tmp_path / "m.yaml"
    p.write_text("name: x\nground: frame\nlinks: [frame, a]\njoints:\n  - {id: A, type: R, links: [frame, b]}\n")
    code, _, err = run_cli("analyze", p)
    assert code == 2
    assert "joints[0].links[1]" in err  # rich markup must not swallow [0]
