"""argparse types of the tools' numeric options: a number in a range, refused before
anything runs with one message that names the value and the range (argparse adds the
option's name and exits with status 2), e.g.
    --jobs: '0' is out of range: allowed a whole number in [1, 1024] workers
    --timeout: 'x' is not a decimal number: allowed a decimal number in (0, 3600] s
Imported by tools/console, tools/demo_main.py, tools/study_engine.py and
tools/bench_fw/bench.py (each puts tools/ on sys.path). Standard library only.
"""
import argparse


def number_in(kind, lo, hi, what="", lo_open=False):
    """An argparse type: an int or float (kind) in [lo, hi], lo excluded with lo_open;
    what (a unit or what the number counts) follows the range in the message."""
    noun = "a whole number" if kind is int else "a decimal number"
    bound = "%d" if kind is int else "%g"
    allowed = ("allowed %s in %s" + bound + ", " + bound + "]%s") % (
        noun, "(" if lo_open else "[", lo, hi, " " + what if what else "")

    def parse(text):
        try:
            v = kind(text)
        except ValueError:
            v = None
        if v is None:
            raise argparse.ArgumentTypeError("'%s' is not %s: %s" % (text, noun, allowed))
        if v != v or v < lo or v > hi or (lo_open and v == lo):  # v != v: a float NaN
            raise argparse.ArgumentTypeError("'%s' is out of range: %s" % (text, allowed))
        return v
    return parse


def whole_in(lo, hi, what=""):
    """An argparse type: a whole number in [lo, hi]."""
    return number_in(int, lo, hi, what)
