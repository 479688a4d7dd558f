#!/usr/bin/python3
"""tools/doc_examples.py against Markdown files written here: an example whose text is
what its commands print passes, one that differs fails (a changed number, a missing
line, a wrong exit status), the wildcards match what they stand for and no more, stdout
and stderr interleave as on a terminal, a transcript outside an example is found unless
excused, and update writes what the commands print."""
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import doc_examples as de  # noqa: E402


def block(*lines):
    return "\n".join("    " + ln if ln else "" for ln in lines)


class DocExamplesTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.tmp.name, "page.md")

    def tearDown(self):
        self.tmp.cleanup()

    def write(self, text):
        with open(self.path, "w") as f:
            f.write(text)

    def examples(self, body, name="e1", opts=""):
        self.write("# page\n\n<!-- example %s%s -->\n%s\n<!-- /example -->\n" % (name, opts, body))
        ex, loose = de.parse_file(self.path)
        self.assertEqual(loose, [])
        return ex

    def verdict(self, body):
        (ex,) = self.examples(body)
        return all(de.matches(e, a) for _c, e, a in de.run_example(ex))

    def test_exact_output_passes_and_a_changed_one_fails(self):
        self.assertTrue(self.verdict(block("$ printf 'T_mean 2.3997 N*m\\nok\\n'",
                                           "T_mean 2.3997 N*m", "ok")))
        self.assertFalse(self.verdict(block("$ printf 'T_mean 2.3997 N*m\\nok\\n'",
                                            "T_mean 2.3753 N*m", "ok")))
        self.assertFalse(self.verdict(block("$ printf 'a\\nb\\n'", "a")))  # a line missing
        self.assertFalse(self.verdict(block("$ printf 'a\\n'", "a", "b")))  # a line too many

    def test_exit_status_is_part_of_the_output(self):
        self.assertTrue(self.verdict(block("$ echo tripped; exit 3", "tripped", "[exit 3]")))
        self.assertFalse(self.verdict(block("$ echo tripped; exit 3", "tripped")))
        self.assertFalse(self.verdict(block("$ echo fine", "fine", "[exit 3]")))

    def test_wildcards(self):
        self.assertTrue(self.verdict(block("$ echo 'done in 12.7 s, pid 4096'",
                                           "done in ... s, pid ...")))
        self.assertFalse(self.verdict(block("$ echo 'done in 12.7 s'", "done at ... s")))
        self.assertTrue(self.verdict(block("$ printf 'a\\nx\\ny\\nb\\n'", "a", "...", "b")))
        self.assertTrue(self.verdict(block("$ printf 'a\\nb\\n'", "a", "...", "b")))  # zero lines
        self.assertFalse(self.verdict(block("$ printf 'a\\nx\\nc\\n'", "a", "...", "b")))
        # "..." inside a line stays within it
        self.assertFalse(self.verdict(block("$ printf 'a 1\\nb 2\\n'", "a ... 2")))

    def test_terminal_order_and_redraws(self):
        # stdout of a C program into a pipe would come after its stderr; on a terminal not
        self.assertTrue(self.verdict(block(
            "$ python3 -c \"import sys; print('first'); print('second', file=sys.stderr)\"",
            "first", "second")))
        self.assertTrue(self.verdict(block(
            "$ printf 'bar 1/3\\rbar 2/3\\r\\033[Kbar 3/3\\ndone\\n'", "bar 3/3", "done")))

    def test_continuation_and_several_commands(self):
        (ex,) = self.examples(block("$ echo one \\", "    two", "one two", "$ echo three", "three"))
        self.assertEqual([c for c, _s, _e in ex.steps], ["echo one \\\n    two", "echo three"])
        self.assertTrue(all(de.matches(e, a) for _c, e, a in de.run_example(ex)))

    def test_timeout_is_reported(self):
        (ex,) = self.examples(block("$ sleep 30", ""), opts=" timeout=1")
        ((_c, _e, actual),) = de.run_example(ex)
        self.assertEqual(actual, ["[timed out after 1 s]"])

    def test_commands_run_beside_the_repository(self):
        self.assertTrue(self.verdict(block("$ test -x tools/doc_examples.py && test ! -e out "
                                           "&& echo repository", "repository")))

    def test_transcripts_outside_examples(self):
        self.write("text\n\n" + block("$ ./tools/sim --list-controllers", "bst 20000 ...") +
                   "\n\ncommands only:\n\n" + block("$ ./tools/test", "$ ./tools/demo") +
                   "\n\n<!-- transcript: a board's output -->\n\n" + block("> status", "ok 10") +
                   "\n\nand one more:\n\n" + block("> status", "ok 10") + "\n")
        ex, loose = de.parse_file(self.path)
        self.assertEqual(ex, [])
        self.assertEqual([p.rsplit(":", 1)[1] for p in loose], ["3", "18"])

    def test_output_without_a_prompt_outside_examples(self):
        """A block that is no list of commands is output (or text) and needs an example or a
        marker: a program's lines without a prompt fail, commands do not (repository
        programs, known ones, sudo, VAR=value, continuations, comments), "not output"
        excuses text but not a transcript."""
        self.write("commands:\n\n" + block(
            "./tools/sim --list-controllers   # the controllers", "tools/console --web \\",
            "    --device /dev/ttyACM0", "sudo ./tools/setup", "PMSM_X=1 \\",
            "    cmake --preset host", "(a few seconds)") +
            "\n\nits output, no prompt:\n\n" + block("controller m2ptfc  fs 10000 Hz") +
            "\n\n<!-- not output: an equation -->\n\n" + block("d' = d + s(i) t_d fs") +
            "\n\n<!-- not output: wrongly -->\n\n" + block("> status", "ok 10") +
            "\n\n<!-- transcript: a board's start-up report -->\n\n" + block("esc1: clock: ok") +
            "\n\na program that is not here:\n\n" + block("tools/nosuch --x") + "\n")
        ex, loose = de.parse_file(self.path)
        self.assertEqual(ex, [])
        self.assertEqual([p.rsplit(":", 1)[1] for p in loose], ["13", "21", "30"])

    def test_malformed_markers_are_errors(self):
        for text in ("<!-- example -->\n" + block("$ true") + "\n<!-- /example -->\n",
                     "<!-- example e -->\n" + block("$ true") + "\n",
                     "<!-- example e label=board -->\n" + block("$ true") + "\n<!-- /example -->\n",
                     "<!-- example e -->\n" + block("no command") + "\n<!-- /example -->\n"):
            self.write(text)
            with self.assertRaises(de.DocError, msg=text):
                de.parse_file(self.path)

    def test_update_writes_what_the_commands_print(self):
        body = block("$ printf 'x 1\\ny 2\\n'", "x 0", "$ echo 'took 3 s'", "took ... s")
        self.examples(body)

        class A:
            names, label = [], None
        (ex,) = de.parse_file(self.path)[0]
        de.collect = lambda: ([ex], [])
        de.cmd_update(A())
        with open(self.path) as f:
            text = f.read()
        self.assertIn(block("$ printf 'x 1\\ny 2\\n'", "x 1", "y 2", "$ echo 'took 3 s'",
                            "took ... s"), text)  # a matching wildcard line is kept
        (ex,) = de.parse_file(self.path)[0]
        self.assertTrue(all(de.matches(e, a) for _c, e, a in de.run_example(ex)))


if __name__ == "__main__":
    unittest.main(verbosity=2)
