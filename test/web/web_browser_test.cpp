// The class pages in a real browser (issue 23), headless chromium against a real lab node
// and web node (web_browser_test.test):
//  - a run page draws its plots: the page reports the pixels drawn in each plot, and a
//    screenshot holds the colours of the velocity steps (ImageMagick counts them);
//  - a student's script sends the pi scene through the start page's form and sees the
//    result: 31 collisions simulated and 31 predicted (m_A/m_B = 100 against a wall: the
//    first two digits of pi).
// Skipped, with a line saying so, when chromium is not installed.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <ros/ros.h>

#include "collision_lab/ros/run_view.h"
#include "../ros/run_collector.h"
// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace {

namespace fs = std::filesystem;
using collision_lab_test::waitUntil;
using nlohmann::json;

constexpr char kUrlParam[] = "/collision_lab/collision_lab_web/url";
/// Virtual time the browser may spend on a page [ms]: it waits for the network, not for this.
constexpr int kBudgetMs = 30000;

std::string output(const std::string& command) {
  std::string text;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return text;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) text += buffer;
  pclose(pipe);
  return text;
}

bool installed(const std::string& program) {
  return std::system(("command -v " + program + " > /dev/null 2>&1").c_str()) == 0;
}

class WebBrowserTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!installed("chromium")) {
      GTEST_SKIP() << "chromium is not installed: browser tests skipped "
                      "(bash scripts/setup_debian.sh --with-screenshots installs it)";
    }
    std::string url;
    ASSERT_TRUE(waitUntil([&] { return ros::param::get(kUrlParam, url); }, "the web node's address"));
    const auto colon = url.rfind(':');
    host_ = url.substr(7, colon - 7);
    port_ = std::stoi(url.substr(colon + 1));
    char pattern[] = "/tmp/collision_lab_web_browser_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    if (!dir_.empty()) fs::remove_all(dir_, ignored);
  }

  std::string chromium(const std::string& what, const std::string& url) const {
    return output("chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1280,1250 "
                  "--user-data-dir=" + dir_ + "/profile --virtual-time-budget=" + std::to_string(kBudgetMs) + " " +
                  what + " '" + url + "' 2>/dev/null");
  }

  std::string host_;
  int port_ = 0;
  std::string dir_;
};

/// data-plots="velocity:N energy:N xt:N" of the page's <body>.
std::map<std::string, long> plotPixels(const std::string& dom) {
  std::map<std::string, long> out;
  std::smatch m;
  if (!std::regex_search(dom, m, std::regex("data-plots=\"([^\"]*)\""))) return out;
  std::istringstream in(m[1].str());
  std::string item;
  while (in >> item) out[item.substr(0, item.find(':'))] = std::stol(item.substr(item.find(':') + 1));
  return out;
}

TEST_F(WebBrowserTest, RunPageDrawsItsPlots) {
  httplib::Client c(host_, port_);
  c.set_read_timeout(60, 0);
  json scene = {{"student", "browser"}, {"preset", "pi_digits_2"}};
  int status = 0;
  std::string body;
  ASSERT_TRUE(waitUntil(
      [&] {
        auto res = c.Post("/api/runs", scene.dump(), "application/json");
        if (!res) return false;
        status = res->status, body = res->body;
        return status != 503;  // 503: the lab node is not subscribed yet
      },
      "the lab node to take inputs"));
  ASSERT_EQ(status, 202) << body;
  const std::string run_id = json::parse(body)["run_id"];
  const std::string page = "http://" + host_ + ":" + std::to_string(port_) + "/runs/" + run_id;

  const std::string dom = chromium("--dump-dom", page);
  EXPECT_NE(dom.find("data-final=\"true\""), std::string::npos) << dom.substr(0, 400);
  const auto pixels = plotPixels(dom);
  for (const char* plot : {"velocity", "energy", "xt"}) {
    ASSERT_TRUE(pixels.count(plot)) << "no plot " << plot << " reported";
    EXPECT_GT(pixels.at(plot), 0) << plot;
  }
  // The phase-space picture: the start and a point after each of the 31 impacts.
  // Elastic: every state on the start's circle (to the 6 digits of the plotted series); the
  // last one in the wedge where no pair approaches.
  EXPECT_NE(dom.find("data-phase=\"31\""), std::string::npos) << dom.substr(0, 600);
  EXPECT_NE(dom.find("data-phase-ends-apart=\"true\""), std::string::npos) << dom.substr(0, 600);
  std::smatch spread;
  ASSERT_TRUE(std::regex_search(dom, spread, std::regex("data-phase-spread=\"([^\"]*)\""))) << dom.substr(0, 600);
  EXPECT_LT(std::stod(spread[1]), 1e-5);
  // Each plot has its numbers as a table (its text alternative): the velocity plot's first
  // row is A at the start, -1 m/s.
  EXPECT_NE(dom.find("class=\"plot_table\""), std::string::npos);
  const std::string tables = chromium("--dump-dom", page + "#open-tables");
  EXPECT_NE(tables.find("<tr><td>v A simulated</td><td>0</td><td>-1</td></tr>"), std::string::npos)
      << tables.substr(tables.find("velocity_box"), 1500);
  EXPECT_NE(tables.find("<th>after collision</th>"), std::string::npos) << "the phase-space table";
  // Each plot's PNG is a slide: 1600 px wide, opaque.
  const std::string checked = chromium("--dump-dom", page + "#check-png");
  for (const char* plot : {"velocity", "energy", "momentum", "energy_bars", "xt"}) {
    EXPECT_TRUE(std::regex_search(checked, std::regex(std::string("data-png=\"[^\"]*\\b") + plot + ":1600x900:opaque")))
        << plot << ": " << checked.substr(0, 600);
  }

  const std::string shot = dir_ + "/run.png";
  chromium("--screenshot=" + shot, page);
  ASSERT_TRUE(fs::exists(shot));
  if (!installed("convert")) {
    std::cout << "ImageMagick is not installed: the screenshot's colours are not counted\n";
    return;
  }
  // The light ball B's velocity steps are drawn in B's colour (rviz's, from the view): 31
  // jumps between about +-10 m/s are thousands of pixels; the scene's dot is about a hundred.
  const std::string b = collision_lab_ros::bodyColourHex(1);
  const long pixels_of_b = std::stol("0" + output("convert " + shot + " -alpha off -fuzz 10% -fill black +opaque '" + b +
                                                  "' -fill white -opaque '" + b + "' -format '%[fx:round(mean*w*h)]' info:"));
  EXPECT_GT(pixels_of_b, 1000) << "the velocity plot looks blank: " << pixels_of_b << " pixels of body B's colour";
}

TEST_F(WebBrowserTest, FormSendsASceneAndSeesTheResult) {
  // The driver page must share the class page's origin to reach into its frame: a proxy on
  // a port of its own serves the driver and forwards everything else to the web node.
  std::ifstream in(std::string(COLLISION_LAB_SOURCE_DIR) + "/test/web/web_form_driver.html");
  std::stringstream driver;
  driver << in.rdbuf();
  httplib::Server proxy;
  const std::string host = host_;
  const int port = port_;
  proxy.Get("/driver", [&](const httplib::Request&, httplib::Response& res) {
    res.set_content(driver.str(), "text/html");
  });
  auto forward = [host, port](const httplib::Request& req, httplib::Response& res) {
    httplib::Client c(host, port);
    c.set_read_timeout(60, 0);
    auto r = req.method == "POST" ? c.Post(req.target.c_str(), req.body, req.get_header_value("Content-Type").c_str())
                                  : c.Get(req.target.c_str());
    if (!r) {
      res.status = 502;
      return;
    }
    res.status = r->status;
    res.set_content(r->body, r->get_header_value("Content-Type").c_str());
  };
  proxy.Get(".*", forward);
  proxy.Post(".*", forward);
  const int proxy_port = proxy.bind_to_any_port("127.0.0.1");
  ASSERT_GT(proxy_port, 0);
  std::thread serving([&] { proxy.listen_after_bind(); });

  const std::string dom = chromium("--dump-dom", "http://127.0.0.1:" + std::to_string(proxy_port) + "/driver");
  proxy.stop();
  serving.join();
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("<pre id=\"result\">([^<]*)</pre>"))) << dom.substr(0, 400);
  const std::string result = m[1];
  EXPECT_NE(result.find("run_id=formbot."), std::string::npos) << result;
  EXPECT_NE(result.find("collisions|31|31|"), std::string::npos) << result;
  EXPECT_EQ(result.find("plots=velocity:0"), std::string::npos) << result;
  // Back on the class page, "My runs" lists the run this browser sent, finished.
  EXPECT_NE(result.find("my_runs=formbot.run1|finished|31"), std::string::npos) << result;
  // The form names bodies in the colours the views will draw: rviz's palette by index for 3
  // bodies (A red, B green, C blue: three different colours), none for 11, which the views
  // colour by start velocity.
  std::smatch colours;
  ASSERT_TRUE(std::regex_search(result, colours, std::regex("colours3=(rgb[^;]*);(rgb[^;]*);(rgb[^\\n]*)\\n"))) << result;
  EXPECT_NE(colours[1], colours[2]);
  EXPECT_NE(colours[2], colours[3]);
  EXPECT_NE(colours[1], colours[3]);
  std::string uncoloured = "colours11=none";
  for (int i = 1; i < 11; ++i) uncoloured += ";none";
  EXPECT_NE(result.find(uncoloured + "\n"), std::string::npos) << result;
}

}  // namespace

/// A number in a data-<name>="..." attribute of the page's <body> (NaN when absent).
double bodyData(const std::string& dom, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(dom, m, std::regex("data-" + name + "=\"([^\"]*)\""))) return std::nan("");
  return std::stod(m[1].str());
}

class RunPageViewTest : public WebBrowserTest {
 protected:
  /// Sends `scene` and returns the final run page's DOM.
  std::string finalPage(const json& scene) {
    httplib::Client c(host_, port_);
    c.set_read_timeout(60, 0);
    int status = 0;
    std::string body;
    EXPECT_TRUE(waitUntil(
        [&] {
          auto res = c.Post("/api/runs", scene.dump(), "application/json");
          if (!res) return false;
          status = res->status, body = res->body;
          return status != 503;
        },
        "the lab node to take inputs"));
    EXPECT_EQ(status, 202) << body;
    if (status != 202) return "";
    const std::string run_id = json::parse(body)["run_id"];
    const std::string page = "http://" + host_ + ":" + std::to_string(port_) + "/runs/" + run_id;
    std::string dom;
    waitUntil(
        [&] {
          dom = chromium("--dump-dom", page);
          return dom.find("data-final=\"true\"") != std::string::npos;
        },
        "the run page to be final");
    return dom;
  }
};

// The pi scene with a cap below its 31 impacts is answered by the model: the page says
// "not simulated" and claims no simulated count or "finished: 31 collisions".
TEST_F(RunPageViewTest, NotSimulatedRunIsShownAsNotSimulated) {
  const std::string dom = finalPage({{"student", "view"}, {"masses", {100, 1, "inf"}}, {"positions", {2, 1, 0}},
                                     {"velocities", {-1, 0, 0}}, {"max_collisions", 10}});
  EXPECT_NE(dom.find("not simulated: "), std::string::npos) << dom.substr(0, 2000);
  EXPECT_EQ(dom.find("finished: 31 collisions"), std::string::npos);
  // No empty chart (an axis from -1 to 1 with nothing on it): the plots are hidden, and in
  // their place why nothing was simulated and the model's answer.
  EXPECT_NE(dom.find("data-plots-hidden=\"velocity energy xt\""), std::string::npos);
  EXPECT_EQ(dom.find("data-plots=\""), std::string::npos) << "a plot was drawn";
  EXPECT_NE(dom.find("<div id=\"not_simulated_box\"><h2>"), std::string::npos) << "the box is hidden";
  EXPECT_NE(dom.find("Nothing to plot, since this run was not simulated: "), std::string::npos);
  EXPECT_NE(dom.find("answered: 31 collisions; final velocities A "), std::string::npos) << dom.substr(0, 3000);
  // No download of what does not exist: the events CSV (a 404) and the plots' PNGs.
  EXPECT_TRUE(std::regex_search(dom, std::regex("<a id=\"dl_csv\"[^>]* hidden")));
  EXPECT_TRUE(std::regex_search(dom, std::regex("<button type=\"button\" data-plot=\"velocity\" hidden")));
}

// Mode predict: the same, whatever the cap.
TEST_F(RunPageViewTest, PredictOnlyRunDrawsNoEmptyChart) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "pi_digits_2"}, {"mode", 1}});
  EXPECT_NE(dom.find("data-plots-hidden=\"velocity energy xt\""), std::string::npos) << dom.substr(0, 2000);
  EXPECT_NE(dom.find("answered: 31 collisions"), std::string::npos);
}

/// The cells of the summary table's row `label`: simulation, prediction, paper (as fmt drew them).
std::vector<std::string> summaryCells(const std::string& dom, const std::string& label) {
  std::smatch m;
  const std::string escaped = std::regex_replace(label, std::regex(R"([\[\]()])"), R"(\$&)");
  if (!std::regex_search(dom, m, std::regex("<th>" + escaped + "</th><td>([^<]*)</td><td>([^<]*)</td><td>([^<]*)</td>"))) {
    return {};
  }
  return {m[1].str(), m[2].str(), m[3].str()};
}

// The first preset a class opens: the model's B ends exactly at rest, as the simulation's
// does (it showed -3.33×10⁻¹⁶ m/s, the closed form's rounding in double), and the largest
// prediction error is 0.
TEST_F(RunPageViewTest, EqualMassesShowsTheModelsBExactlyAtRest) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "equal_masses"}});
  const std::vector<std::string> b = summaryCells(dom, "final v B [m/s]");
  ASSERT_EQ(b.size(), 3u) << dom.substr(0, 3000);
  EXPECT_EQ(b[0], "0");  // simulated
  EXPECT_EQ(b[1], "0");  // the model's
  EXPECT_EQ(summaryCells(dom, "final v A [m/s]").at(1), "1");
  EXPECT_EQ(summaryCells(dom, "final v C [m/s]").at(1), "-1");
  const std::vector<std::string> error = summaryCells(dom, "max prediction error (ratio)");
  ASSERT_EQ(error.size(), 3u);
  EXPECT_EQ(error[0], "0");
  // The paper's printed final velocities carry momentum and energy the scene never had
  // (1.375, 1.375, -0.25 m/s: 2.5 kg m/s against 0, 1.921875 J against 1 J).
  EXPECT_EQ(summaryCells(dom, "momentum at the start [kg m/s]").at(0), "0");
  EXPECT_EQ(summaryCells(dom, "momentum at the end [kg m/s]"), (std::vector<std::string>{"0", "0", "2.5"}));
  EXPECT_EQ(summaryCells(dom, "kinetic energy at the start [J]").at(0), "1");
  EXPECT_EQ(summaryCells(dom, "kinetic energy at the end [J]"), (std::vector<std::string>{"1", "1", "1.921875"}));
  // The paper's column explained: (2.15)/(2.16) keep neither, beside the correct formula;
  // (3.22)'s count beside the correct one and the simulated one.
  EXPECT_NE(dom.find("<div id=\"paper_box\">"), std::string::npos);
  EXPECT_NE(dom.find("<td>no: 2.5 kg m/s after, 0 before</td><td>no: 1.92188 J after, 1 before</td>"), std::string::npos)
      << dom.substr(dom.find("paper_box"), 2000);
  EXPECT_NE(dom.find(", 3 correct, 3 simulated</td>"), std::string::npos);
}

// A moving wall does work: the page says so, and its energy rows show the change.
TEST_F(RunPageViewTest, AMovingWallsWorkIsNamed) {
  const std::string dom = finalPage({{"student", "lesson"}, {"preset", "moving_wall"}});
  EXPECT_NE(dom.find("a wall moves: a body that hits it gains or loses kinetic energy"), std::string::npos) << dom.substr(0, 2000);
  const auto start = summaryCells(dom, "kinetic energy at the start [J]");
  const auto end = summaryCells(dom, "kinetic energy at the end [J]");
  ASSERT_EQ(start.size(), 3u);
  ASSERT_EQ(end.size(), 3u);
  EXPECT_NE(start[0], end[0]);
}

// The state after the last collision shows: the collision-index axis ends one past it, as
// rviz's does (it ended at the last collision, whose heat was a line on the right border).
// (Student "lesson": the page allows 10 runs per student a minute, and "view" sends many.)
TEST_F(RunPageViewTest, TheStateAfterTheLastCollisionIsDrawn) {
  const std::string dom = finalPage({{"student", "lesson"}, {"masses", {2, 1}}, {"positions", {1, 0}},
                                     {"velocities", {-1, 1}}, {"restitution", {0.5}}});
  EXPECT_EQ(bodyData(dom, "index-axis-end"), 2.0) << dom.substr(0, 2000);
  EXPECT_EQ(summaryCells(dom, "heat [J]").at(0), "1");
  EXPECT_EQ(bodyData(finalPage({{"student", "lesson"}, {"preset", "equal_masses"}}), "index-axis-end"), 4.0);
}

// No collision: the bodies still fly apart on every plot, and no events CSV link leads to a 404.
// Inelastic (e = 0.5 between equal masses): the point spirals inside the start's circle.
TEST_F(RunPageViewTest, InelasticRunsSpiralInPhaseSpace) {
  const std::string dom = finalPage({{"student", "phase"}, {"masses", {1, 1, 1}}, {"positions", {2, 1, -1}},
                                     {"velocities", {-1, 0, 1}}, {"restitution", {0.5}}});
  EXPECT_NE(dom.find("data-phase-ends-apart=\"true\""), std::string::npos) << dom.substr(0, 600);
  EXPECT_GT(bodyData(dom, "phase-spread"), 0.1);
}

// A run stopped at its cap shows where it stopped, not "final" velocities; a run the model
// answered over its cap says how to simulate it.
TEST_F(RunPageViewTest, AStoppedRunSaysWhereItStoppedAndACappedOneHowToSimulateIt) {
  std::string dom = finalPage({{"student", "cap"}, {"preset", "ball_between_walls"}, {"max_collisions", 100}});
  EXPECT_EQ(summaryCells(dom, "v B [m/s] (simulated: at the stop, after collision 100)").size(), 3u) << dom.substr(0, 3000);
  EXPECT_TRUE(summaryCells(dom, "final v B [m/s]").empty());
  dom = finalPage({{"student", "cap"}, {"masses", {1e6, 1, "inf"}}, {"positions", {2, 1, 0}},
                   {"velocities", {-1, 0, 0}}, {"max_collisions", 100}});
  EXPECT_NE(dom.find("set \"Stop after\" (max_collisions) to at least 3,141"), std::string::npos) << dom.substr(0, 3000);
}

// A long run read in a window: the first 1% of ball_between_walls (999.5 s), every event.
TEST_F(RunPageViewTest, ALongRunIsReadInATimeWindow) {
  const std::string dom = finalPage({{"student", "window"}, {"preset", "ball_between_walls"}});
  const std::string run_id = dom.substr(dom.find("data-run-id=\"") + 13, dom.find('"', dom.find("data-run-id=\"") + 13) - dom.find("data-run-id=\"") - 13);
  const std::string windowed = chromium("--dump-dom", "http://" + host_ + ":" + std::to_string(port_) + "/runs/" + run_id + "#xt-early");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(windowed, m, std::regex("data-xt-window=\"0-([0-9.]+):([0-9]+)\""))) << windowed.substr(0, 800);
  const double to = std::stod(m[1]);
  EXPECT_GE(to, 999.5 / 100);
  EXPECT_LE(to, 2 * 1049.5 / 100);  // a round number above 1% of the run's end
  EXPECT_GE(std::stoi(m[2]), 1);
  EXPECT_NE(windowed.find("every event."), std::string::npos);
}

// What is conserved, in words, from the server's exact totals: equal masses keep momentum
// (0) and energy (1 J); an inelastic pair keeps momentum and turns energy into heat.
TEST_F(RunPageViewTest, ConservationIsSaidInWords) {
  std::string dom = finalPage({{"student", "keep"}, {"preset", "equal_masses"}});
  EXPECT_NE(dom.find("<li>Momentum: 0 kg m/s at the start and 0 kg m/s at the end: conserved"), std::string::npos)
      << dom.substr(dom.find("conservation"), 1500);
  EXPECT_NE(dom.find("<li>Energy: 1 J at the start and 1 J at the end: conserved, since every collision is elastic.</li>"),
            std::string::npos);
  EXPECT_NE(dom.find("moving at 0 m/s; at the end at 0 m/s (the same: no outside force acts).</li>"), std::string::npos);
  // Two 1 kg carts at e = 0.5 (preset two_carts_inelastic: 2 m/s against 0): momentum 2,
  // heat (1 - e^2) mu v^2 / 2 = 0.75 * 0.5 * 4 / 2 = 0.75 J of the 2 J.
  dom = finalPage({{"student", "keep"}, {"masses", {1, 1}}, {"positions", {1, 0}}, {"velocities", {0, 2}}, {"restitution", {0.5}}});
  EXPECT_NE(dom.find("<li>Momentum: 2 kg m/s at the start and 2 kg m/s at the end: conserved"), std::string::npos)
      << dom.substr(dom.find("conservation"), 1500);
  EXPECT_NE(dom.find("<li>Energy: 2 J at the start, 1.25 J at the end: 0.75 J turned into heat"), std::string::npos);
}

TEST_F(RunPageViewTest, ManyBodiesHaveNoPhaseSpacePicture) {
  const std::string dom = finalPage({{"student", "phase"}, {"preset", "cradle_5"}});
  EXPECT_NE(dom.find("data-phase=\"none\""), std::string::npos) << dom.substr(0, 600);
}

TEST_F(RunPageViewTest, NoCollisionDrawsTheBodiesFlyingApart) {
  const std::string dom = finalPage({{"student", "lesson"}, {"preset", "no_collision"}});
  const auto pixels = plotPixels(dom);
  for (const char* plot : {"velocity", "energy", "xt"}) {
    ASSERT_TRUE(pixels.count(plot)) << dom.substr(0, 2000);
    EXPECT_GT(pixels.at(plot), 0) << plot;
  }
  EXPECT_GT(bodyData(dom, "xt-end"), 0.0);
  EXPECT_TRUE(std::regex_search(dom, std::regex("<a id=\"dl_csv\"[^>]*hidden"))) << dom.substr(0, 3000);
}

// cluster_collapse_5 collapses twice (A..C at t = 3.5 s, A..E at t = 10.43 s): both are
// named, and the counter counts both.
TEST_F(RunPageViewTest, EveryCollapseIsNamedAndCounted) {
  const std::string dom = finalPage({{"student", "lesson"}, {"preset", "cluster_collapse_5"}});
  EXPECT_NE(dom.find("16 collisions + 2 collapses"), std::string::npos) << dom.substr(0, 2000);
  EXPECT_NE(dom.find("collapse 2 at t = 10.4335 s"), std::string::npos);
}

TEST_F(RunPageViewTest, CollapseIsNamed) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "collapse_equal"}});
  EXPECT_NE(dom.find("collapse at t = "), std::string::npos) << dom.substr(0, 2000);
}

// collapse_equal a billion times smaller collapses at t = 3.5 ns: the view's text (rviz's
// "3.5×10^-9") is in the page's number style. (Failed before: the facts read "×10^-9".)
TEST_F(RunPageViewTest, TheViewsNumbersAreInThePagesStyle) {
  const std::string dom = finalPage({{"student", "view"},
                                     {"masses", {1, 1, 1}},
                                     {"positions", {2e-9, 1e-9, 0}},
                                     {"velocities", {-1, 0, 0}},
                                     {"restitution", 0.05}});
  EXPECT_NE(dom.find("collapse at t = 3.5×10⁻⁹ s"), std::string::npos) << dom.substr(0, 3000);
  EXPECT_EQ(dom.find("×10^"), std::string::npos) << dom.substr(dom.find("×10^") == std::string::npos ? 0 : dom.find("×10^") - 200, 400);
}

// The two carts part after their impact at t = 0.5 s: every x-t line reaches the run's end.
TEST_F(RunPageViewTest, WorldlinesReachTheRunsEnd) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "two_carts"}});
  const double end = bodyData(dom, "view-end"), reached = bodyData(dom, "xt-end");
  ASSERT_TRUE(std::isfinite(end)) << dom.substr(0, 2000);
  EXPECT_GT(end, 0.5);
  EXPECT_DOUBLE_EQ(reached, end);
}

// A ring is named, its lines are cut at the seam, and the 24 bodies shown have a legend.
TEST_F(RunPageViewTest, RingIsNamedAndCutAtTheSeam) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "granular_ring"}, {"max_collisions", 2000}});
  EXPECT_NE(dom.find("ring of 1,000 m"), std::string::npos) << dom.substr(0, 2000);
  EXPECT_NE(dom.find("24 of 1,000 bodies, evenly spaced, the outermost two included"), std::string::npos);
  const double jump = bodyData(dom, "xt-max-jump");
  ASSERT_TRUE(std::isfinite(jump));
  EXPECT_LT(jump, 500.0) << "an x-t segment spans the seam";
}

TEST_F(RunPageViewTest, BoxOfManyBodiesHasItsLegend) {
  const std::string dom = finalPage({{"student", "view"}, {"preset", "granular_box_1000"}, {"max_collisions", 2000}});
  EXPECT_NE(dom.find("box: walls at both ends"), std::string::npos) << dom.substr(0, 2000);
  EXPECT_NE(dom.find("24 of 1,002 bodies, evenly spaced, the outermost two included"), std::string::npos);
  // One colour per body, rviz's (the view's): each body's start velocity's, not ten
  // repeating ones, and the page says what they mean. (Failed before: the sketch drew the
  // shown bodies in the palette's ten colours, the others grey.)
  EXPECT_NE(dom.find("Colour: velocity at the start, blue: moving left"), std::string::npos);
  EXPECT_GT(bodyData(dom, "scene-colours"), 100.0);
  // A gas (e = 0.9): T(t) on log-log axes with Haff's law fitted.
  EXPECT_NE(dom.find("Haff's law T = T0 / (1 + t/τ)² fitted: T0 = "), std::string::npos);
  EXPECT_NE(dom.find("How well it fits: the rms misfit of ln T is "), std::string::npos);
  EXPECT_GT(bodyData(dom, "temperature-points"), 10.0);
  EXPECT_GT(bodyData(dom, "haff-tau"), 0.0);
  // T said in a student's words, not as "T = sum m (v - V)^2 / N".
  EXPECT_NE(dom.find("twice the mean kinetic energy of the bodies' motion relative to their centre of mass [J]"),
            std::string::npos);
  EXPECT_EQ(dom.find("sum m (v - V)^2"), std::string::npos);
  // The log axes' labels: 1, 2 or 5 times a power of ten (or decades only), never e-notation.
  for (const char* axis : {"x", "y"}) {
    std::smatch m;
    const std::string name = std::string("data-temperature-ticks-") + axis + "=\"([^\"]*)\"";
    ASSERT_TRUE(std::regex_search(dom, m, std::regex(name))) << axis;
    std::istringstream labels(m[1].str());
    std::string label;
    int count = 0;
    while (std::getline(labels, label, '|')) {
      ++count;
      EXPECT_EQ(label.find('e'), std::string::npos) << axis << ": " << label;
      EXPECT_TRUE(std::regex_match(label, std::regex("([125]×)?10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+|0\\.0[125]|0\\.[125]|[125]|[125]0|[125]00|[125],000")))
          << axis << ": " << label;
    }
    EXPECT_GE(count, 2) << axis << ": " << m[1];
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "web_browser_test");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
