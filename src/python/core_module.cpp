// collision_lab._core: the Python module's C++ part (pybind11). Runs scenes in process
// through scene_driver.h, without the GIL, and turns Ctrl-C (a pending KeyboardInterrupt)
// into the engine's cancel flag.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <future>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "scene_driver.h"

namespace py = pybind11;

namespace collision_lab {
namespace python {
namespace {

/// One scene: the CLI's arguments and the scene's name.
using SceneArgs = std::pair<std::vector<std::string>, std::string>;

/// Runs `work` on its own thread while the calling thread, without the GIL, checks for
/// Python signals every 50 ms. A signal handler that raises (SIGINT: KeyboardInterrupt)
/// sets `cancel`; once `work` has returned, true says so and that exception is pending (the
/// caller raises it, or another). Exceptions of `work` are rethrown (pybind11 turns them
/// into Python's).
template <class Work>
bool runWatchingSignals(std::atomic<bool>& cancel, Work work) {
  std::exception_ptr failure;
  std::promise<void> done;
  std::future<void> finished = done.get_future();
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    std::thread worker([&] {
      try {
        work();
      } catch (...) {
        failure = std::current_exception();
      }
      done.set_value();
    });
    while (finished.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      if (interrupted) continue;
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) {  // the handler's exception is now the pending error
        interrupted = true;
        cancel.store(true);
      }
    }
    worker.join();
  }
  if (interrupted) return true;
  if (failure) std::rethrow_exception(failure);
  return false;
}

/// The report of one scene and whether Ctrl-C stopped it: then the report is of the run as
/// far as it went (its summary cancelled), and the KeyboardInterrupt is cleared for the
/// caller to raise with it. Any other pending exception is raised as it is.
std::pair<std::string, bool> runJson(const std::vector<std::string>& args, const std::string& name) {
  std::atomic<bool> cancel{false};
  std::string json;
  std::exception_ptr failure;
  const bool interrupted = runWatchingSignals(cancel, [&] {
    try {
      json = runSceneJson(args, name, &cancel);
    } catch (...) {
      failure = std::current_exception();
    }
  });
  // Only Ctrl-C with a report to show becomes RunInterrupted: another handler's exception
  // (a timeout, sys.exit) and a run that failed keep theirs.
  if (interrupted && (failure || json.empty() || !PyErr_ExceptionMatches(PyExc_KeyboardInterrupt))) {
    throw py::error_already_set();
  }
  if (failure) std::rethrow_exception(failure);
  if (interrupted) PyErr_Clear();
  return {json, interrupted};
}

/// Every scene on `workers` threads (each takes the next scene not yet taken); the reports
/// in the scenes' order. Ctrl-C cancels every run that has not finished.
std::vector<std::string> runManyJson(const std::vector<SceneArgs>& scenes, unsigned workers) {
  std::atomic<bool> cancel{false};
  std::vector<std::string> reports(scenes.size());
  const bool interrupted = runWatchingSignals(cancel, [&] {
    std::atomic<std::size_t> next{0};
    std::vector<std::exception_ptr> failures(std::max(1u, workers));
    const auto drain = [&](std::exception_ptr& failure) {
      try {
        for (std::size_t i = next++; i < scenes.size(); i = next++) {
          reports[i] = runSceneJson(scenes[i].first, scenes[i].second, &cancel);
        }
      } catch (...) {
        failure = std::current_exception();
        next = scenes.size();  // the others stop after their current scene
      }
    };
    std::vector<std::thread> threads;
    for (std::size_t t = 1; t < failures.size(); ++t) threads.emplace_back(drain, std::ref(failures[t]));
    drain(failures[0]);
    for (std::thread& thread : threads) thread.join();
    for (const std::exception_ptr& failure : failures) {
      if (failure) std::rethrow_exception(failure);
    }
  });
  if (interrupted) throw py::error_already_set();
  return reports;
}

}  // namespace
}  // namespace python
}  // namespace collision_lab

PYBIND11_MODULE(_core, m) {
  m.doc() = "collision_lab's C++ core, run in process: the CLI's JSON report of a scene.";
  m.attr("version") = COLLISION_LAB_VERSION;  // package.xml's, as the node's RunParameters
  m.def("run_json", &collision_lab::python::runJson, py::arg("args"), py::arg("name"),
        "(report, interrupted): the CLI's JSON report (or JSON error) of one scene given as "
        "collision_lab_cli's arguments, and whether Ctrl-C cancelled it (the report is then of the run "
        "as far as it went). Runs without the GIL.");
  m.def("run_many_json", &collision_lab::python::runManyJson, py::arg("scenes"), py::arg("workers"),
        "run_json of every (args, name) pair on `workers` C++ threads, without the GIL; the reports in order.");
}
