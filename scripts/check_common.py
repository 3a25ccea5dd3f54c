"""What the CTest check scripts (check_fos.py, check_body_plateau.py) share."""
import argparse
import subprocess
import sys


def split_extra(argv=None):
    """The script's own arguments and, after a `--`, those passed on to rktsph."""
    argv = sys.argv[1:] if argv is None else argv
    if "--" in argv:
        return argv[: argv.index("--")], argv[argv.index("--") + 1:]
    return argv, []


def parser(doc):
    """The arguments every check takes: the binary, the case, the output folder and the window
    [low, high] the checked figure must lie in."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--binary", required=True)
    p.add_argument("--case", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--low", type=float, required=True)
    p.add_argument("--high", type=float, required=True)
    return p


def run(cmd, what):
    """Run rktsph, echoing the command; exit with a message if it fails."""
    print(" ".join(cmd), flush=True)
    rc = subprocess.call(cmd)
    if rc != 0:
        sys.exit("rktsph {} exited with status {}".format(what, rc))
