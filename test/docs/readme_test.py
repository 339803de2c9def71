#!/usr/bin/python3
"""README.md is the front door: short, the two commands first, every link to a file alive.

- at most kMaxLines lines (the rest lives in docs/ and is linked);
- the two commands (`bash scripts/demo.sh`, `bash scripts/test.sh`) within its first
  kTopLines lines, and the catkin route (catkin_make, rosrun, roslaunch) in it;
- every relative link names a file of the repository, and every `#anchor` into a Markdown
  file a heading of that file (GitHub's rule: lower case, spaces as '-', punctuation out).

Usage: readme_test.py --repo DIR [--gtest_output=xml:FILE] [--text]
"""
import argparse
import os
import re
import sys
import unittest

kMaxLines = 250
kTopLines = 40
kLink = re.compile(r"\]\(([^)\s]+)\)")


def anchor(heading):
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path):
    return {anchor(line.lstrip("#")) for line in open(path) if line.startswith("#")}


class Readme(unittest.TestCase):
    repo = None

    def setUp(self):
        self.path = os.path.join(self.repo, "README.md")
        self.lines = open(self.path).read().rstrip("\n").split("\n")

    def test_at_most_250_lines(self):
        self.assertLessEqual(len(self.lines), kMaxLines)

    def test_the_two_commands_come_first_and_the_catkin_route_is_there(self):
        top = "\n".join(self.lines[:kTopLines])
        self.assertIn("bash scripts/demo.sh", top)
        self.assertIn("bash scripts/test.sh", top)
        text = "\n".join(self.lines)
        for command in ("catkin_make", "rosrun collision_lab", "roslaunch collision_lab"):
            self.assertIn(command, text)

    def test_every_link_to_a_file_is_alive(self):
        dead = []
        for number, line in enumerate(self.lines, 1):
            for target in kLink.findall(line):
                if re.match(r"[a-z]+:", target):
                    continue  # http:, https:, mailto:
                file, _, fragment = target.partition("#")
                path = os.path.join(self.repo, file) if file else self.path
                if not os.path.exists(path):
                    dead.append(f"README.md:{number}: {target}: no such file")
                elif fragment and path.endswith(".md") and fragment not in anchors(path):
                    dead.append(f"README.md:{number}: {target}: no heading '{fragment}' in {file or 'README.md'}")
        self.assertEqual(dead, [])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repo", required=True)
    args, rest = parser.parse_known_args()
    Readme.repo = os.path.abspath(args.repo)
    import rosunit
    rosunit.unitrun("collision_lab", "readme", Readme, sysargs=[sys.argv[0]] + rest)


if __name__ == "__main__":
    main()
