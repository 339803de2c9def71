#!/usr/bin/python3
"""Runs a gtest binary's tests in parallel, one test per process, and writes one JUnit file.

For the long CPU-bound test binaries (the core and N-body physics tests), which would
otherwise hold CI on one core. Each test runs alone in its own process (--gtest_filter), at
most --jobs at a time, in the binary's listing order. Each test's output is printed as it
finishes; the closing lines are gtest's ("[  PASSED  ] N tests.", "[  FAILED  ] Suite.Name").
The XML file has gtest's layout (a testsuites root with the totals, one testsuite per suite),
so catkin_test_results counts it as it counted the serial run (skipped tests as skipped;
the binaries have no disabled ones). A test without a result (no XML, none in it, or one
that does not parse) or whose process ends with a non-zero status and no failure in its
XML (a crash, an abort) is a failure, with its output's tail.

Usage: gtest_parallel.py BINARY --gtest_output=xml:FILE [--jobs N]
Exit status: 0 when every test passed, 1 otherwise.
"""
import argparse
import concurrent.futures
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET


def listed_tests(binary):
    """The binary's tests as "Suite.Name", in its listing order (disabled ones left out)."""
    out = subprocess.run([binary, "--gtest_list_tests"], check=True, capture_output=True, text=True).stdout
    tests, suite = [], None
    for line in out.splitlines():
        if not line.strip():
            continue
        name = line.split("#")[0].strip()
        if not line.startswith(" "):
            suite = name
        elif not name.startswith("DISABLED_") and not suite.startswith("DISABLED_"):
            tests.append(suite + name)
    return tests


def run_one(binary, test, folder, index):
    xml = os.path.join(folder, "%05d.xml" % index)
    # Each test in full: gtest's own sharding would leave some processes without their test.
    environment = {k: v for k, v in os.environ.items() if k not in ("GTEST_SHARD_INDEX", "GTEST_TOTAL_SHARDS")}
    done = subprocess.run([binary, "--gtest_filter=" + test, "--gtest_output=xml:" + xml], env=environment,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    return test, done.returncode, done.stdout, xml


def testcases(test, returncode, output, xml):
    """The test's <testcase> elements from its XML. A failure when there is no result (no
    file, no test case in it, a file that does not parse: the test did not run, whatever
    the status) or when the process failed without saying so (a crash after the result)."""
    try:
        cases = list(ET.parse(xml).getroot().iter("testcase")) if os.path.exists(xml) else []
    except ET.ParseError:
        cases = []
    problem = None
    if not cases:
        suite, name = test.split(".", 1)
        cases = [ET.Element("testcase", name=name, classname=suite, status="run", time="0")]
        problem = "no result from the test process (status %d)" % returncode
    elif returncode != 0 and not any(failed(case) for case in cases):
        problem = "the test process ended with status %d" % returncode
    if problem:
        failure = ET.SubElement(cases[-1], "failure", message=problem)
        failure.text = output[-4000:]
    return cases


def failed(case):
    return case.find("failure") is not None or case.find("error") is not None


def skipped(case):
    return case.find("skipped") is not None


def merged(results):
    """gtest's layout: the root with the totals, then one <testsuite> per suite in run order."""
    suites = {}
    for test, returncode, output, xml in results:
        for case in testcases(test, returncode, output, xml):
            suites.setdefault(case.get("classname"), []).append(case)
    root = ET.Element("testsuites", name="AllTests")
    totals = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0, "disabled": 0, "time": 0.0}
    for name, cases in suites.items():
        suite = ET.SubElement(root, "testsuite", name=name)
        counts = {"tests": len(cases), "failures": sum(failed(c) for c in cases), "errors": 0,
                  "skipped": sum(skipped(c) for c in cases), "disabled": 0,
                  "time": sum(float(c.get("time", "0")) for c in cases)}
        for key, value in counts.items():
            suite.set(key, "%.3f" % value if key == "time" else str(value))
            totals[key] += value
        suite.extend(cases)
    for key, value in totals.items():
        root.set(key, "%.3f" % value if key == "time" else str(value))
    return ET.ElementTree(root)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("--gtest_output", required=True, help="xml:FILE, as gtest takes it")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    if not args.gtest_output.startswith("xml:"):
        parser.error("--gtest_output takes xml:FILE")
    result_file = args.gtest_output[len("xml:"):]
    tests = listed_tests(args.binary)
    print("[==========] Running %d tests from %s in %d processes at a time." % (len(tests), args.binary, args.jobs),
          flush=True)
    with tempfile.TemporaryDirectory() as folder, \
            concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(run_one, args.binary, test, folder, k) for k, test in enumerate(tests)]
        for future in concurrent.futures.as_completed(futures):
            print(future.result()[2], end="", flush=True)
        results = [future.result() for future in futures]
        tree = merged(results)
    os.makedirs(os.path.dirname(os.path.abspath(result_file)), exist_ok=True)
    tree.write(result_file, encoding="UTF-8", xml_declaration=True)
    failures = ["%s.%s" % (c.get("classname"), c.get("name")) for c in tree.getroot().iter("testcase") if failed(c)]
    print("[==========] %d tests ran." % len(tests))
    print("[  PASSED  ] %d tests." % (len(tests) - len(failures)))
    for name in failures:
        print("[  FAILED  ] %s" % name)
    return 1 if failures or not tests else 0


if __name__ == "__main__":
    sys.exit(main())
