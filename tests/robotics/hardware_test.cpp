// Hardware adapters: the FRI-like datagrams, the UDP adapter against the robot simulator as a real process
// on 127.0.0.1 (lost, damaged and wrong-version answers, a killed and restarted simulator), the simulated
// fieldbus drive and its adapter, and HardwareBinding running the JointController against them by config.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "simulator_process.hpp"
#include "test_util.hpp"
#include "vsd/robotics.hpp"

namespace vsd::robotics {
namespace {

using vsd_example::SimulatorProcess;

// ---- the datagrams ---------------------------------------------------------------------------------------

fri::Message sample_state() {
  fri::Message m;
  m.kind = fri::Kind::State;
  m.sequence = 0xDEADBEEF;
  m.flags = 0;
  m.time = 12.5;
  m.position = {0.1, -0.2, 3.0};
  m.velocity = {1.0, 2.0, -3.0};
  return m;
}

TEST(FriProtocol, RoundTripsEveryField) {
  const fri::Message m = sample_state();
  const auto bytes = fri::encode(m);
  ASSERT_EQ(bytes.size(), fri::datagram_size(3));
  EXPECT_EQ(bytes[0], 'V');
  EXPECT_EQ(bytes[4], fri::protocol_version);
  EXPECT_EQ(bytes[8], 0xEF);  // little-endian sequence
  const fri::Decoded d = fri::decode(bytes);
  ASSERT_EQ(d.error, fri::DecodeError::None) << d.what;
  EXPECT_EQ(d.message.kind, fri::Kind::State);
  EXPECT_EQ(d.message.sequence, 0xDEADBEEFu);
  EXPECT_EQ(d.message.time, 12.5);
  EXPECT_EQ(d.message.position, m.position);
  EXPECT_EQ(d.message.velocity, m.velocity);
  // A command without velocities carries zeros.
  fri::Message c;
  c.position = {1.0};
  EXPECT_EQ(fri::decode(fri::encode(c)).message.velocity, std::vector<double>{0.0});
}

TEST(FriProtocol, Crc32IsTheIeeeOne) {
  const std::string text = "123456789";
  EXPECT_EQ(fri::crc32(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size())),
            0xCBF43926u);
}

TEST(FriProtocol, RejectsMalformedDatagramsWithAReason) {
  const auto good = fri::encode(sample_state());
  auto with = [&](auto change) {
    auto b = good;
    change(b);
    return fri::decode(b);
  };
  EXPECT_EQ(fri::decode(std::span(good.data(), 5)).error, fri::DecodeError::TooShort);
  EXPECT_EQ(with([](auto& b) { b[0] = 'X'; }).error, fri::DecodeError::BadMagic);
  const auto v2 = with([](auto& b) { b[4] = 2; });
  EXPECT_EQ(v2.error, fri::DecodeError::WrongVersion);
  EXPECT_EQ(v2.version, 2);
  EXPECT_EQ(v2.what, "protocol version 2, expected 1");
  EXPECT_EQ(with([](auto& b) { b[5] = 9; }).error, fri::DecodeError::BadKind);
  EXPECT_EQ(with([](auto& b) { b[6] = 4; }).error, fri::DecodeError::BadLength);
  EXPECT_EQ(with([](auto& b) { b.push_back(0); }).error, fri::DecodeError::BadLength);
  // Any flipped bit after the version byte is caught (by the length check or the checksum).
  for (std::size_t i = 5; i < good.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      auto b = good;
      b[i] ^= static_cast<std::uint8_t>(1U << bit);
      EXPECT_NE(fri::decode(b).error, fri::DecodeError::None) << "byte " << i << " bit " << bit;
    }
  fri::Message too_many;
  too_many.position.assign(fri::max_joints + 1, 0.0);
  EXPECT_THROW((void)fri::encode(too_many), vsd::Error);
  fri::Message mismatched = sample_state();
  mismatched.velocity.pop_back();
  EXPECT_THROW((void)fri::encode(mismatched), vsd::Error);
}

// ---- the UDP adapter against the simulator process -----------------------------------------------------

std::vector<std::string> args(std::initializer_list<std::string> a) { return a; }

UdpOptions udp_options(std::uint16_t port, int dof) {
  UdpOptions o;
  o.port = port;
  o.dof = dof;
  o.reply_timeout = 0.2;  // generous: the machine may be loaded (and ASan slows the simulator down)
  o.max_missed = 3;
  return o;
}

TEST(UdpAdapter, FollowsCommandsOfTheSimulatorProcess) {
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "3", "--initial", "0.5,0,-0.5"}));
  ASSERT_NE(sim.port(), 0);
  UdpAdapter robot(udp_options(sim.port(), 3));
  EXPECT_EQ(robot.describe(), "udp 127.0.0.1:" + std::to_string(sim.port()));
  robot.connect();
  EXPECT_NE(robot.local_port(), 0);
  robot.cycle(0.01);  // no command yet: hold
  ASSERT_TRUE(robot.read().fresh) << robot.fault_message();
  EXPECT_EQ(robot.read().position, (std::vector<double>{0.5, 0.0, -0.5}));
  const std::vector<double> target{0.52, 0.01, -0.45};
  robot.write(target);
  robot.cycle(0.01);
  ASSERT_EQ(robot.fault(), AdapterFault::None) << robot.fault_message();
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(robot.read().position[i], target[i], 1e-15);
  EXPECT_NEAR(robot.read().velocity[2], 5.0, 1e-9);  // 0.05 rad in 10 ms
  EXPECT_NEAR(robot.read().time, 0.02, 1e-15);
  EXPECT_EQ(robot.stats().received, 2u);
  EXPECT_EQ(robot.stats().missed, 0u);
  EXPECT_THROW(robot.write(std::vector<double>{1.0}), vsd::Error);
}

TEST(UdpAdapter, ALostAnswerIsHeldAndCountedNotAFault) {
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "2", "--drop-every", "3"}));
  UdpOptions o = udp_options(sim.port(), 2);
  o.reply_timeout = 0.5;  // generous: under ASan and a loaded machine a reply can take long
  UdpAdapter robot(o);
  robot.connect();
  int stale = 0;
  for (int k = 1; k <= 9; ++k) {
    robot.write(std::vector<double>{0.001 * k, 0.0});
    robot.cycle(0.01);
    if (!robot.read().fresh) {
      ++stale;
      EXPECT_EQ(k % 3, 0) << "cycle " << k;
      EXPECT_NEAR(robot.read().position[0], 0.001 * (k - 1), 1e-15);  // the last good state is kept
    }
    EXPECT_EQ(robot.fault(), AdapterFault::None) << robot.fault_message();
  }
  EXPECT_EQ(stale, 3);
  EXPECT_EQ(robot.stats().missed, 3u);
}

TEST(UdpAdapter, DamagedAnswersAreRejected) {
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "2", "--garble-every", "2"}));
  UdpOptions o = udp_options(sim.port(), 2);
  o.reply_timeout = 0.5;  // generous: under ASan and a loaded machine a reply can take long
  UdpAdapter robot(o);
  robot.connect();
  for (int k = 1; k <= 6; ++k) {
    robot.write(std::vector<double>{0.01 * k, 0.0});
    robot.cycle(0.01);
    EXPECT_EQ(robot.read().fresh, k % 2 == 1) << "cycle " << k;
  }
  EXPECT_EQ(robot.stats().rejected, 3u);
  EXPECT_NE(robot.last_rejection().find("CRC-32"), std::string::npos) << robot.last_rejection();
  EXPECT_EQ(robot.fault(), AdapterFault::None);
  EXPECT_NEAR(robot.read().position[0], 0.05, 1e-15);  // cycle 5's state, never a damaged one
}

TEST(UdpAdapter, APeerOfAnotherVersionIsAProtocolFault) {
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "2", "--wrong-version-every", "1"}));
  UdpOptions o = udp_options(sim.port(), 2);
  o.reply_timeout = 0.5;  // generous: under ASan and a loaded machine a reply can take long
  UdpAdapter robot(o);
  robot.connect();
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(robot.fault(), AdapterFault::None);
    robot.cycle(0.01);
  }
  EXPECT_EQ(robot.fault(), AdapterFault::Protocol);
  EXPECT_NE(robot.fault_message().find("protocol version 2, expected 1"), std::string::npos)
      << robot.fault_message();
  EXPECT_FALSE(robot.read().valid);
  EXPECT_EQ(robot.stats().faults, 1u);
}

TEST(UdpAdapter, AWrongJointCountIsReportedByTheRobot) {
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "7"}));
  UdpAdapter robot(udp_options(sim.port(), 6));
  robot.connect();
  robot.cycle(0.01);
  EXPECT_EQ(robot.fault(), AdapterFault::Device);
  EXPECT_NE(robot.fault_message().find("wrong joint count"), std::string::npos) << robot.fault_message();
}

TEST(UdpAdapter, AKilledSimulatorIsATimeoutFaultAndARestartRecovers) {
  auto sim =
      std::make_unique<SimulatorProcess>(VSD_ROBOT_SIMULATOR, args({"--dof", "2", "--initial", "1,2"}));
  const std::uint16_t port = sim->port();
  UdpOptions o = udp_options(port, 2);
  o.reply_timeout = 0.3;
  UdpAdapter robot(o);
  robot.connect();
  robot.cycle(0.01);
  ASSERT_TRUE(robot.read().fresh);
  sim->kill();
  for (int k = 0; k < 3; ++k) robot.cycle(0.01);
  EXPECT_EQ(robot.fault(), AdapterFault::Timeout);
  EXPECT_NE(robot.fault_message().find("does not answer"), std::string::npos) << robot.fault_message();
  EXPECT_EQ(robot.read().position, (std::vector<double>{1.0, 2.0}));  // the last state is kept
  // The robot comes back on its port (a new process, starting where the old one stood).
  sim = std::make_unique<SimulatorProcess>(
      VSD_ROBOT_SIMULATOR, args({"--dof", "2", "--initial", "1,2", "--port", std::to_string(port)}));
  robot.cycle(0.01);
  for (int k = 0; k < 20 && !robot.read().fresh; ++k) robot.cycle(0.01);
  EXPECT_EQ(robot.fault(), AdapterFault::None) << robot.fault_message();
  EXPECT_EQ(robot.stats().recoveries, 1u);
  EXPECT_TRUE(robot.read().fresh);
}

TEST(UdpAdapter, RefusesOtherThanLoopbackAndBadOptions) {
  UdpOptions o;
  o.host = "192.0.2.1";
  o.port = 4000;
  UdpAdapter outside(o);
  EXPECT_THROW(outside.connect(), vsd::Error);
  o.host = "localhost";
  o.port = 0;
  UdpAdapter no_port(o);
  EXPECT_THROW(no_port.connect(), vsd::Error);
  o.dof = 0;
  EXPECT_THROW(UdpAdapter{o}, vsd::Error);
  o.dof = 3;
  o.reply_timeout = 0;
  EXPECT_THROW(UdpAdapter{o}, vsd::Error);
  // Not connected: a Connection fault, no crash.
  UdpAdapter idle(udp_options(4000, 2));
  idle.cycle(0.01);
  EXPECT_EQ(idle.fault(), AdapterFault::Connection);
}

// ---- the fieldbus drive and adapter --------------------------------------------------------------------

TEST(Fieldbus, StatusWordsFollowCiA402) {
  using fieldbus::DriveState;
  for (DriveState s : {DriveState::SwitchOnDisabled, DriveState::ReadyToSwitchOn, DriveState::SwitchedOn,
                       DriveState::OperationEnabled, DriveState::Fault})
    EXPECT_EQ(fieldbus::state_of(fieldbus::status_word(s)), s) << fieldbus::to_string(s);
  EXPECT_EQ(fieldbus::state_of(0x0237), DriveState::OperationEnabled);  // other bits are ignored
  fieldbus::ProcessImage image;
  image.set_target_position(-123456);
  EXPECT_EQ(image.target_position(), -123456);
  EXPECT_EQ(image.outputs[4], 0xC0);  // little-endian two's complement
}

TEST(Fieldbus, EnablesMovesWithinTheSpeedLimitAndHolds) {
  FieldbusOptions o;
  o.initial_position = 0.3;
  o.drive.max_velocity = 0.2;
  FieldbusAxisAdapter axis(o);
  axis.connect();
  // shutdown, switch on, enable operation: three cycles until the state is fresh.
  std::vector<fieldbus::DriveState> seen;
  for (int k = 0; k < 3; ++k) {
    axis.cycle(0.01);
    seen.push_back(axis.drive().state());
  }
  EXPECT_EQ(seen, (std::vector{fieldbus::DriveState::ReadyToSwitchOn, fieldbus::DriveState::SwitchedOn,
                               fieldbus::DriveState::OperationEnabled}));
  ASSERT_TRUE(axis.read().fresh);
  EXPECT_NEAR(axis.read().position[0], 0.3, 1e-6);
  axis.write(std::vector<double>{0.31});  // 1 cm: needs 5 cycles at 0.2 m/s
  axis.cycle(0.01);
  EXPECT_NEAR(axis.read().position[0], 0.302, 1e-6);
  EXPECT_NEAR(axis.read().velocity[0], 0.2, 1e-4);
  for (int k = 0; k < 5; ++k) axis.cycle(0.01);
  EXPECT_NEAR(axis.read().position[0], 0.31, 1e-6);
  axis.hold();
  axis.cycle(0.01);
  EXPECT_NEAR(axis.read().position[0], 0.31, 1e-6);
  EXPECT_EQ(axis.image().control_word(), fieldbus::control::enable_operation);
  EXPECT_EQ(axis.fault(), AdapterFault::None);
}

TEST(Fieldbus, AFollowingErrorFaultsUntilReset) {
  FieldbusAxisAdapter axis;
  axis.connect();
  for (int k = 0; k < 3; ++k) axis.cycle(0.01);
  axis.write(std::vector<double>{0.5});  // 0.5 m away in one cycle
  axis.cycle(0.01);
  EXPECT_EQ(axis.fault(), AdapterFault::Device);
  EXPECT_NE(axis.fault_message().find("0x8611 (following error)"), std::string::npos) << axis.fault_message();
  EXPECT_EQ(axis.drive().state(), fieldbus::DriveState::Fault);
  for (int k = 0; k < 5; ++k) axis.cycle(0.01);  // stays in fault without a reset
  EXPECT_EQ(axis.fault(), AdapterFault::Device);
  axis.hold();
  axis.reset_fault();
  for (int k = 0; k < 4; ++k) axis.cycle(0.01);  // reset edge, then the enable sequence
  EXPECT_EQ(axis.fault(), AdapterFault::None) << axis.fault_message();
  EXPECT_TRUE(axis.read().fresh);
  EXPECT_EQ(axis.stats().recoveries, 1u);
  axis.drive().inject_fault();
  axis.cycle(0.01);
  EXPECT_NE(axis.fault_message().find("0x9000"), std::string::npos);
  axis.write(std::vector<double>{2.5});  // outside the travel range after the next reset
  axis.reset_fault();
  for (int k = 0; k < 5; ++k) axis.cycle(0.01);  // reset, enable (targets the actual position), command
  EXPECT_NE(axis.fault_message().find("travel range"), std::string::npos) << axis.fault_message();
}

TEST(Fieldbus, BadSetupAndABusThatIsOff) {
  FieldbusOptions o;
  o.drive.max_velocity = 0;
  EXPECT_THROW(FieldbusAxisAdapter{o}, vsd::Error);
  o = {};
  o.drive.upper = 1e6;  // does not fit 32-bit counts at 1 µm
  EXPECT_THROW(FieldbusAxisAdapter{o}, vsd::Error);
  FieldbusAxisAdapter off;
  off.cycle(0.01);
  EXPECT_EQ(off.fault(), AdapterFault::Connection);
  o = {};
  o.enable_timeout = 2;
  FieldbusAxisAdapter stuck(o);
  stuck.connect();
  stuck.drive().inject_fault();
  stuck.cycle(0.01);
  EXPECT_EQ(stuck.fault(), AdapterFault::Device);
}

// ---- configuration and the binding ---------------------------------------------------------------------

TEST(HardwareConfig, ParsesAdaptersAndRejectsNonsense) {
  EXPECT_TRUE(parse_hardware_config("sim").empty());
  EXPECT_TRUE(parse_hardware_config("  ").empty());
  const auto c = parse_hardware_config("udp://127.0.0.1:4000?joints=a,b&timeout=0.01; fieldbus://?joints=c");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].kind, "udp");
  EXPECT_EQ(c[0].address, "127.0.0.1:4000");
  EXPECT_EQ(c[0].joints, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(c[0].options.at("timeout"), "0.01");
  EXPECT_EQ(c[1].kind, "fieldbus");
  EXPECT_EQ(c[1].joints, std::vector<std::string>{"c"});
  EXPECT_THROW((void)parse_hardware_config("can://x"), vsd::Error);
  EXPECT_THROW((void)parse_hardware_config("udp://h:1?joints"), vsd::Error);
  EXPECT_THROW((void)make_adapter(parse_hardware_config("udp://127.0.0.1")[0], 2), vsd::Error);
  EXPECT_THROW((void)make_adapter(parse_hardware_config("udp://127.0.0.1:99999")[0], 2), vsd::Error);
  EXPECT_THROW((void)make_adapter(parse_hardware_config("udp://127.0.0.1:9?speed=1")[0], 2), vsd::Error);
  EXPECT_THROW((void)make_adapter(parse_hardware_config("fieldbus://?velocity=fast")[0], 1), vsd::Error);
  EXPECT_THROW((void)make_adapter(parse_hardware_config("fieldbus://")[0], 2), vsd::Error);
  EXPECT_NO_THROW((void)make_adapter(parse_hardware_config("fieldbus://?velocity=0.3")[0], 1));
}

// The iiwa with a controller and a binding, stepped by the Scheduler.
struct HardwareCell {
  Environment env;
  KinematicTree* tree = nullptr;
  JointController* ctrl = nullptr;
  HardwareBinding* hw = nullptr;
  explicit HardwareCell(const std::string& config) {
    env.use<Module>();
    scene::UrdfOptions o;
    o.load_meshes = false;
    auto rep = scene::load_urdf(env.main_state().database(), vsd_test::robot_file("iiwa14.urdf"), o);
    tree = &build_kinematics(*rep.scene);
    ctrl = &env.main_state().create<JointController>();
    rep.scene->add_extension(*ctrl);
    hw = &env.main_state().create<HardwareBinding>();
    hw->set_config(config);
    rep.scene->add_extension(*hw);
    env.scheduler().set_base_step(0.01);
  }
};

// Steps at least once (a new target is planned in the first step), then until the controller is done.
void run_until_done(Environment& env, JointController& ctrl, int max_steps) {
  env.step();
  for (int k = 1; k < max_steps && !ctrl.done(); ++k) env.step();
}

std::string udp_config(std::uint16_t port) {
  return "udp://127.0.0.1:" + std::to_string(port) + "?timeout=0.5&max_missed=2";
}

TEST(HardwareBinding, TheSameControllerRunsInSimulationOrAgainstTheSimulatorProcess) {
  const std::vector<double> goal{0.3, -0.2, 0.1, -0.5, 0.2, 0.3, -0.1};
  std::vector<double> reached[2];
  SimulatorProcess sim(VSD_ROBOT_SIMULATOR, args({"--dof", "7"}));
  for (int run = 0; run < 2; ++run) {
    HardwareCell c(run == 0 ? "sim" : udp_config(sim.port()));
    c.ctrl->set_target(goal);
    c.ctrl->set_mode(ControlMode::Position);
    run_until_done(c.env, *c.ctrl, 200);
    EXPECT_TRUE(c.ctrl->done());
    EXPECT_EQ(c.hw->status(), run == 0 ? BindingStatus::Simulation : BindingStatus::Running) << c.hw->fault();
    reached[run] = c.tree->positions();
    if (run == 1) {
      EXPECT_EQ(c.hw->adapter_count(), 1u);
      EXPECT_GT(c.hw->adapter(0).stats().received, 10u);
      // The database shows what the robot measured.
      EXPECT_EQ(c.hw->adapter(0).read().position, reached[1]);
    }
  }
  for (std::size_t i = 0; i < goal.size(); ++i) {
    EXPECT_NEAR(reached[0][i], goal[i], 1e-12);
    EXPECT_NEAR(reached[1][i], goal[i], 1e-12);
  }
}

TEST(HardwareBinding, ADeadRobotHoldsTheControllerAndReportsTheFaultUntilItIsBack) {
  auto sim = std::make_unique<SimulatorProcess>(VSD_ROBOT_SIMULATOR, args({"--dof", "7"}));
  const std::uint16_t port = sim->port();
  HardwareCell c(udp_config(port));
  std::vector<BindingStatus> changes;
  auto conn = c.env.main_state()
                  .on_property_changed(HardwareBinding::static_meta(), true)
                  .connect([&](SimStateInstance& i, const MetaProperty& p) {
                    if (p.name() == "status") changes.push_back(static_cast<HardwareBinding&>(i).status());
                  });
  const std::vector<double> goal{1.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0};
  c.ctrl->set_target(goal);
  c.ctrl->set_mode(ControlMode::Position);
  for (int k = 0; k < 20; ++k) c.env.step();
  ASSERT_EQ(c.hw->status(), BindingStatus::Running) << c.hw->fault();
  ASSERT_FALSE(c.ctrl->done());
  sim->kill();
  for (int k = 0; k < 3; ++k) c.env.step();
  EXPECT_EQ(c.hw->status(), BindingStatus::Fault);
  EXPECT_NE(c.hw->fault().find("does not answer"), std::string::npos) << c.hw->fault();
  EXPECT_EQ(c.hw->fault_count(), 1);
  const std::vector<double> held = c.tree->positions();
  for (int k = 0; k < 5; ++k) c.env.step();
  EXPECT_EQ(c.tree->positions(), held);  // holding: nothing moves while the robot is away
  EXPECT_TRUE(c.hw->holding());
  // The robot is back where it stopped; the controller replans from there and arrives.
  std::string initial;
  for (double v : held) initial += (initial.empty() ? "" : ",") + vsd_test::num(v);
  sim = std::make_unique<SimulatorProcess>(
      VSD_ROBOT_SIMULATOR, args({"--dof", "7", "--port", std::to_string(port), "--initial", initial}));
  run_until_done(c.env, *c.ctrl, 400);
  EXPECT_EQ(c.hw->status(), BindingStatus::Running) << c.hw->fault();
  EXPECT_TRUE(c.hw->fault().empty());
  EXPECT_TRUE(c.ctrl->done());
  const auto q = c.tree->positions();
  for (std::size_t i = 0; i < goal.size(); ++i) EXPECT_NEAR(q[i], goal[i], 1e-12);
  ASSERT_GE(changes.size(), 3u);
  EXPECT_EQ(changes[0], BindingStatus::Connecting);
  EXPECT_NE(std::find(changes.begin(), changes.end(), BindingStatus::Fault), changes.end());
  EXPECT_EQ(changes.back(), BindingStatus::Running);
}

TEST(HardwareBinding, ABadConfigurationIsAFaultNotASimulation) {
  HardwareCell c("udp://127.0.0.1:4000?joints=no_such_joint");
  c.ctrl->set_target(std::vector<double>(7, 0.2));
  c.ctrl->set_mode(ControlMode::Position);
  c.env.step();
  EXPECT_EQ(c.hw->status(), BindingStatus::Fault);
  EXPECT_NE(c.hw->fault().find("no joint 'no_such_joint'"), std::string::npos) << c.hw->fault();
  c.env.step();
  EXPECT_EQ(c.tree->positions(), std::vector<double>(7, 0.0));  // held
  c.hw->set_config("udp://127.0.0.1:4000?joints=iiwa_joint_1;fieldbus://?joints=iiwa_joint_1");
  c.env.step();
  EXPECT_NE(c.hw->fault().find("bound twice"), std::string::npos) << c.hw->fault();
  c.hw->set_config("sim");  // by configuration only: back to the simulated robot
  run_until_done(c.env, *c.ctrl, 100);
  EXPECT_EQ(c.hw->status(), BindingStatus::Simulation);
  EXPECT_NEAR(c.tree->positions()[0], 0.2, 1e-12);
}

TEST(HardwareBinding, ALinearAxisOnTheFieldbusBesideASimulatedArm) {
  // A DH chain: a prismatic axis carrying two rotary joints; only the axis is bound (the arm stays
  // simulated).
  Environment env;
  env.use<Module>();
  auto& base = env.main_state().create<scene::Scene>();
  env.main_state().database().add_child(base);
  const std::vector<DhJoint> rows = {
      {"axis", KinematicJointType::Prismatic, {0.0, 0.0, 0.0, 0.0}, true, -1.0, 1.0, 0.5},
      {"j1", KinematicJointType::Rotary, {0.3, 0.0, 0.1, 0.0}, true, -3.0, 3.0, 2.0},
      {"j2", KinematicJointType::Rotary, {0.2, 0.0, 0.0, 0.0}, true, -3.0, 3.0, 2.0}};
  KinematicTree& tree = build_dh_chain(base, DhConvention::Standard, rows);
  auto& ctrl = env.main_state().create<JointController>();
  base.add_extension(ctrl);
  auto& hw = env.main_state().create<HardwareBinding>();
  hw.set_config("fieldbus://sim?joints=axis&velocity=1");
  base.add_extension(hw);
  env.scheduler().set_base_step(0.01);
  ctrl.set_target(std::vector<double>{0.4, 0.5, -0.5});
  ctrl.set_mode(ControlMode::Position);
  run_until_done(env, ctrl, 300);
  ASSERT_TRUE(ctrl.done()) << hw.fault();
  EXPECT_EQ(hw.status(), BindingStatus::Running);
  const auto q = tree.positions();
  EXPECT_NEAR(q[0], 0.4, 1e-6);  // measured, in 1 µm counts
  EXPECT_NEAR(q[1], 0.5, 1e-12);
  auto& axis = static_cast<FieldbusAxisAdapter&>(hw.adapter(0));
  EXPECT_EQ(hw.adapter_joints(0), std::vector<int>{0});
  // A drive fault holds everything until it is reset.
  ctrl.set_target(std::vector<double>{-0.4, 0.0, 0.0});
  env.step();
  axis.drive().inject_fault();
  env.step();
  EXPECT_EQ(hw.status(), BindingStatus::Fault);
  EXPECT_NE(hw.fault().find("drive fault 0x9000"), std::string::npos) << hw.fault();
  const auto held = tree.positions();
  for (int k = 0; k < 5; ++k) env.step();
  EXPECT_EQ(tree.positions(), held);
  hw.reset_faults();
  run_until_done(env, ctrl, 400);
  EXPECT_EQ(hw.status(), BindingStatus::Running) << hw.fault();
  EXPECT_TRUE(ctrl.done());
  EXPECT_NEAR(tree.positions()[0], -0.4, 1e-6);
  EXPECT_NEAR(tree.positions()[2], 0.0, 1e-12);
}

}  // namespace
}  // namespace vsd::robotics
