"""Issue 33's done-when command, exactly as written, after sourcing the devel space."""
import os
import subprocess

DONE_WHEN = ("import collision_lab as c; print(c.run([100, 1, float('inf')], [2, 1, 0], "
             "[-1, 0, 0]).summary['collision_count'])")


def test_done_when_command_prints_31():
    # The test's environment is the sourced workspace (the README's test command).
    out = subprocess.run(['/usr/bin/python3', '-c', DONE_WHEN], check=True, capture_output=True,
                         text=True, cwd='/', env=os.environ).stdout
    assert out == '31\n'
