// The fixture of the tests that race two writers in one process: the robot controller (seeds the state,
// "robot"), the user interface ("ui") and a third participant that only watches ("monitor"), each on its
// own Environment and all synced before a test starts. The conflicts the robot and the ui are told of
// are collected. A test fills the robot's state in populate(), before anyone joins.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dist_test_util.hpp"

namespace vsd_dist_test {

struct ThreeParticipants : testing::Test {
  std::uint32_t domain = fresh_domain();
  vsd::Environment env_r{1}, env_u{2}, env_c{3};
  vsd::SimState& r = env_r.main_state();
  vsd::SimState& u = env_u.main_state();
  vsd::SimState& c = env_c.main_state();
  std::vector<std::string> log_r, log_u, log_c;
  std::unique_ptr<vsd::dist::Participant> robot, ui, other;
  std::vector<vsd::dist::Conflict> seen_r, seen_u;
  vsd::Connection cr, cu;

  /// What the robot's state holds before the others join.
  virtual void populate() {}

  void SetUp() override {
    populate();
    robot = std::make_unique<vsd::dist::Participant>(r, options("robot", domain, true, &log_r));
    ui = std::make_unique<vsd::dist::Participant>(u, options("ui", domain, false, &log_u));
    other = std::make_unique<vsd::dist::Participant>(c, options("monitor", domain, false, &log_c));
    ASSERT_TRUE(
        poll_all({robot.get(), ui.get(), other.get()}, [&] { return ui->synced() && other->synced(); }));
    cr = robot->on_conflict().connect([&](const vsd::dist::Conflict& x) { seen_r.push_back(x); });
    cu = ui->on_conflict().connect([&](const vsd::dist::Conflict& x) { seen_u.push_back(x); });
  }

  /// Polls all three until @p f holds (false after the poll timeout).
  bool settle(const std::function<bool()>& f) { return poll_all({robot.get(), ui.get(), other.get()}, f); }
};

}  // namespace vsd_dist_test
