// Faults: foreign and malformed samples, diverged states, participants that die, processes, and (as root)
// two network namespaces with packet loss, delay and reordering.
#include <dds/dds.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>

#include "dist_test_util.hpp"
#include "vsd/core/bytes.hpp"
#include "vsd_dist.h"

using namespace std::chrono_literals;
using testing::HasSubstr;
using vsd_dist_test::contains;
using vsd_dist_test::DArm;
using vsd_dist_test::options;
using vsd_dist_test::poll_all;

namespace {

// A raw Cyclone DDS writer on vsd::dist's topic, for samples no participant would send.
struct RawWriter {
  dds_entity_t participant, topic, writer;
  explicit RawWriter(std::uint32_t domain) {
    participant = dds_create_participant(domain, nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(2));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    topic = dds_create_topic(participant, &vsd_dist_Message_desc, "vsd", qos, nullptr);
    writer = dds_create_writer(participant, topic, qos, nullptr);
    dds_delete_qos(qos);
  }
  ~RawWriter() { dds_delete(participant); }
  bool wait_matched(std::size_t n) {
    const auto end = std::chrono::steady_clock::now() + 10s;
    dds_publication_matched_status_t st{};
    while (std::chrono::steady_clock::now() < end) {
      dds_get_publication_matched_status(writer, &st);
      if (st.current_count >= n) return true;
      std::this_thread::sleep_for(2ms);
    }
    return false;
  }
  void send(std::uint64_t sender, std::uint64_t seq, std::uint8_t kind, std::vector<std::uint8_t> payload,
            std::uint64_t clock = 0) {
    vsd_dist_Message m{};
    m.sender = sender;
    m.seq = seq;
    m.clock = clock;
    m.kind = kind;
    m.payload._buffer = payload.data();
    m.payload._length = static_cast<std::uint32_t>(payload.size());
    m.payload._maximum = m.payload._length;
    ASSERT_GE(dds_write(writer, &m), 0);
    dds_write_flush(writer);  // the loopback configuration batches writes
  }
};

std::vector<std::uint8_t> envelope(std::vector<std::uint8_t> body) {
  body.insert(body.begin(), {'V', 'S', 'D', 'D', 2});
  return body;
}

// A sample's payload holding a wire bundle (docs/dist.md) of one operation @p op on instance @p id whose
// name table is @p name alone (the class of a creation, the property of a set or list edit); @p rest
// writes what follows the operation's name index.
std::vector<std::uint8_t> one_op(const std::string& name, std::uint8_t op, vsd::Id id,
                                 const std::function<void(vsd::ByteWriter&)>& rest) {
  std::vector<std::uint8_t> body{'V', 'S', 'D', 'W', 2};
  vsd::ByteWriter w(body);
  w.varint(1);
  w.string(name);
  w.varint(1);
  w.u8(op);
  w.varint(id);
  w.varint(0);
  rest(w);
  return envelope(body);
}

struct FaultTest : testing::Test {
  std::uint32_t domain = vsd_dist_test::fresh_domain();
  vsd::Environment env_a{1}, env_b{2};
  vsd::SimState& a = env_a.main_state();
  vsd::SimState& b = env_b.main_state();
  std::vector<std::string> log_a, log_b;
  DArm* arm = nullptr;
  void SetUp() override {
    arm = &a.create<DArm>();
    a.database().add_child(*arm);
  }
};

TEST_F(FaultTest, ForeignAndMalformedSamplesAreLoggedAndNeverApplied) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  RawWriter raw(domain);
  ASSERT_TRUE(raw.wait_matched(2));
  const std::size_t before = b.size();

  raw.send(77, 1, 1, {'h', 'e', 'l', 'l', 'o'});                          // no envelope
  raw.send(77, 1, 1, {'V', 'S', 'D', 'D', 9, 0});                         // a future version
  raw.send(77, 1, 42, envelope({}));                                      // unknown kind
  raw.send(77, 1, 1, envelope({'V', 'S', 'D', 'W', 2, 0, 1, 1, 1, 99}));  // bundle: bad name index
  raw.send(77, 2, 1, envelope({0xff, 0xff, 0xff}));                       // bundle: garbage
  raw.send(77, 0, 5, envelope({1, 2}));                                   // a truncated report
  // A well-formed bundle that creates an instance of a class nobody has: decodes, cannot apply.
  std::vector<std::uint8_t> body{'V', 'S', 'D', 'W', 2, 1, 7,  'N', 'o', 'C',
                                 'l', 'a', 's', 's', 1, 1, 99, 0,   0};
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.stats().foreign >= 3 && pb.stats().malformed >= 3; }));
  EXPECT_EQ(b.size(), before);
  EXPECT_TRUE(contains(log_b, "rejected a foreign sample from 000000000000004d (5 bytes): no VSDD envelope"));
  EXPECT_TRUE(contains(log_b, "unsupported envelope version"));
  EXPECT_TRUE(contains(log_b, "unknown message kind"));
  EXPECT_TRUE(contains(log_b,
                       "rejected bundle 1 of 000000000000004d: wire bundle byte 9: name index 99 is past the "
                       "name table (0 names)"))
      << testing::PrintToString(log_b);
  EXPECT_TRUE(contains(log_b, "rejected bundle 2 of"));
  EXPECT_TRUE(contains(log_a, "no VSDD envelope"));  // everybody rejects them
  EXPECT_EQ(pb.stats().resyncs, 0u);

  // A sender whose bundle decodes but does not apply: the receiver resynchronises, says so, and ends
  // equal to the others.
  raw.send(78, 1, 1, envelope(body));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return contains(log_b, "does not apply here"); }));
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return pb.synced() && pa.synced(); }, 15s));
  EXPECT_TRUE(contains(log_b, "unknown class 'NoClass'"));
  EXPECT_EQ(b.size(), before);

  arm->set_target(4.0);  // and the real stream goes on
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return b.find<DArm>(arm->id())->target() == 4.0; }, 15s));
}

// A list edit that names an entry nobody has (a third participant's insertion still on the way, or a
// broken sender): the receivers resynchronise and say so; the state stays the shared one.
TEST_F(FaultTest, AnEditOfAnUnknownListEntryResynchronises) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  RawWriter raw(domain);
  ASSERT_TRUE(raw.wait_matched(2));
  raw.send(80, 1, 1, one_op("tools", 7, arm->id(), [&](vsd::ByteWriter& w) {  // erase entry (5, 0x77, 1)
             w.varint(5);
             w.fixed(std::uint64_t{0x77});
             w.varint(1);
             w.varint(arm->id());
           }));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return contains(log_b, "it edits a list entry unknown here"); }))
      << testing::PrintToString(log_b);
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return pb.synced() && pa.synced(); }, 15s));
  arm->set_target(6.0);  // and the real stream goes on
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return b.find<DArm>(arm->id())->target() == 6.0; }, 15s));
  std::string diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
}

// Bundles are not delivered in causal order: a bundle that inserts after an entry made by a third
// participant's bundle that has not arrived yet waits for it, and both apply, in order, without a resync.
TEST_F(FaultTest, AnEditOfAnEntryStillOnTheWayWaitsForIt) {
  auto& n1 = a.create<vsd::Node>();
  auto& n2 = a.create<vsd::Node>();
  a.database().add_child(n1);
  a.database().add_child(n2);
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  RawWriter raw(domain);
  ASSERT_TRUE(raw.wait_matched(2));
  auto insert = [&](std::uint64_t origin_clock, std::uint64_t origin_who, std::uint64_t origin_n,
                    vsd::Id target) {
    return one_op("tools", 6, arm->id(), [&](vsd::ByteWriter& w) {  // entry 1 of the bundle, after the origin
      w.varint(1);
      w.varint(origin_clock);
      w.fixed(origin_who);
      w.varint(origin_n);
      w.varint(target);
    });
  };
  // Participant 0x90 saw 0x91's entry (clock 5) and inserted after it (clock 10); 0x91's bundle comes later.
  raw.send(0x90, 1, 1, insert(5, 0x91, 1, n2.id()), 10);
  raw.send(0x91, 1, 1, insert(0, 0, 0, n1.id()), 5);
  const std::vector<vsd::Id> want{n1.id(), n2.id()};
  auto tools = [&](vsd::SimState& s) {
    std::vector<vsd::Id> v;
    for (vsd::Node* n : s.find<DArm>(arm->id())->tools()) v.push_back(n->id());
    return v;
  };
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return tools(a) == want && tools(b) == want; }))
      << testing::PrintToString(tools(a)) << " " << testing::PrintToString(log_b);
  EXPECT_GE(pa.stats().bundles_waited, 1u);
  EXPECT_GE(pb.stats().bundles_waited, 1u);
  EXPECT_EQ(pa.stats().resyncs + pb.stats().resyncs, 0u);
}

// The same for references: participant 0x90 saw 0x91 create a node and pointed the arm's `watched` at it
// (clock 10); 0x91's creation (clock 5) arrives after it. The reference waits for the creation instead of
// making its receivers resynchronise.
TEST_F(FaultTest, AReferenceToAnInstanceStillOnTheWayWaitsForIt) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  RawWriter raw(domain);
  ASSERT_TRUE(raw.wait_matched(2));
  const vsd::Id made = 0x91000005;  // an id of the third participant's range, unused here
  ASSERT_EQ(a.find(made), nullptr);
  // 0x90's set of arm.watched (the value's length, then the reference's id), and 0x91's creation.
  raw.send(0x90, 1, 1,
           one_op("watched", 3, arm->id(),
                  [&](vsd::ByteWriter& w) {
                    std::vector<std::uint8_t> v;
                    vsd::ByteWriter(v).varint(made);
                    w.varint(v.size());
                    for (std::uint8_t x : v) w.u8(x);
                  }),
           10);
  raw.send(
      0x91, 1, 1,
      one_op(std::string(vsd::Node::static_meta().name()), 1, made, [](vsd::ByteWriter& w) { w.varint(0); }),
      5);
  auto watched = [&](vsd::SimState& s) -> vsd::Id {
    const vsd::Node* n = s.find<DArm>(arm->id())->watched().get();
    return n != nullptr ? n->id() : vsd::null_id;
  };
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return watched(a) == made && watched(b) == made; }))
      << testing::PrintToString(log_a) << " " << testing::PrintToString(log_b);
  EXPECT_GE(pa.stats().bundles_waited + pb.stats().bundles_waited, 1u);
  EXPECT_EQ(pa.stats().resyncs + pb.stats().resyncs, 0u) << testing::PrintToString(log_b);
  std::string diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
}

// A reference to an instance nobody makes: after the wait, the receivers resynchronise and drop it alike.
TEST_F(FaultTest, AReferenceToAnInstanceNobodyMakesResynchronisesAfterTheWait) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  RawWriter raw(domain);
  ASSERT_TRUE(raw.wait_matched(2));
  raw.send(0x92, 1, 1,
           one_op("watched", 3, arm->id(),
                  [](vsd::ByteWriter& w) {
                    w.varint(4);  // the value: a 4-byte varint id nobody has
                    w.varint(0x0abcdef0);
                  }),
           3);
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return pb.stats().resyncs >= 1 && pb.synced() && pa.synced(); }, 15s))
      << testing::PrintToString(log_b);
  EXPECT_GE(pb.stats().bundles_waited, 1u);
  EXPECT_EQ(b.find<DArm>(arm->id())->watched().get(), nullptr);
  arm->set_target(7.0);  // and the real stream goes on
  ASSERT_TRUE(poll_all(
      {&pa, &pb}, [&] { return b.find<DArm>(arm->id())->target() == 7.0; }, 15s));
  std::string diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
}

TEST_F(FaultTest, ADivergedParticipantResynchronisesFromASnapshot) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  vsd::dist::Participant pb(b, options("b", domain, false, &log_b));
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.synced(); }));
  // b loses the arm behind the participant's back (not recorded, never sent): its state has diverged.
  (void)b.stop_recording();
  b.destroy(*b.find(arm->id()));
  b.start_recording();
  arm->set_target(3.0);
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return pb.stats().resyncs == 1 && pb.synced(); }));
  EXPECT_TRUE(contains(log_b, "bundle 1 of 'a' does not apply here"));
  EXPECT_TRUE(contains(log_b, "resynchronising from a snapshot"));
  ASSERT_NE(b.find<DArm>(arm->id()), nullptr);
  EXPECT_EQ(b.find<DArm>(arm->id())->target(), 3.0);
  std::string diff;
  EXPECT_TRUE(a.equals(b, &diff)) << diff;
  arm->set_target(5.0);  // bundle 2 was in the snapshot's wake: applied once
  ASSERT_TRUE(poll_all({&pa, &pb}, [&] { return b.find<DArm>(arm->id())->target() == 5.0; }));
  EXPECT_EQ(pb.stats().resyncs, 1u);
}

TEST_F(FaultTest, AParticipantThatDiesAndRejoinsCatchesUp) {
  vsd::dist::Participant pa(a, options("a", domain, true, &log_a));
  {
    vsd::Environment env_c{3};
    vsd::dist::Participant pc(env_c.main_state(), options("c", domain));
    ASSERT_TRUE(poll_all({&pa, &pc}, [&] { return pc.synced(); }));
    arm->set_counter(1);
    ASSERT_TRUE(
        poll_all({&pa, &pc}, [&] { return env_c.main_state().find<DArm>(arm->id())->counter() == 1; }));
  }  // c dies with its state
  for (int i = 2; i <= 50; ++i) {
    arm->set_counter(i);
    pa.poll();
  }
  auto& extra = a.create<DArm>();
  arm->add_child(extra);
  vsd::Environment env_c2{4};
  vsd::dist::Participant pc2(env_c2.main_state(), options("c", domain));
  ASSERT_TRUE(poll_all({&pa, &pc2}, [&] { return pc2.synced(); }));
  std::string diff;
  EXPECT_TRUE(a.equals(env_c2.main_state(), &diff)) << diff;
  EXPECT_EQ(env_c2.main_state().find<DArm>(arm->id())->counter(), 50);
}

// ---- processes -------------------------------------------------------------------------------------------

std::pair<int, std::string> run(const std::string& command) {
  std::string out;
  FILE* f = ::popen(("( " + command + " ) 2>&1").c_str(), "r");
  if (f == nullptr) return {-1, "popen failed"};
  std::array<char, 512> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), f) != nullptr) out += buf.data();
  const int status = ::pclose(f);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

TEST(DistProcesses, AReaderThatDiesAndARejoinerFollowAWriterProcess) {
  const std::string peer = VSD_DIST_PEER;
  const std::string d = std::to_string(vsd_dist_test::fresh_domain());
  // The writer counts to 3000; a reader dies after 300 values; a second reader joins mid-stream.
  const auto [rc, out] =
      run("timeout 90 " + peer + " writer " + d + " 3000 & W=$!; " +  //
          "timeout 60 " + peer + " reader " + d + " 3000 --die-after 300; " + "timeout 60 " + peer +
          " reader " + d + " 3000; R=$?; wait $W; W=$?; " + "[ $R -eq 0 ] && [ $W -eq 0 ]");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_THAT(out, HasSubstr("reader: dying after 300 values"));
  EXPECT_THAT(out,
              testing::ContainsRegex("reader: synced at [0-9]+, then [0-9]+ values in order, final 3000"));
  EXPECT_THAT(out, HasSubstr("writer: a reader is done"));
}

// Packet loss without netem: Cyclone DDS's own test option Internal/Test/XmitLossiness drops the given
// share of outgoing packets (per mille) in both processes; the reliable protocol must repair every loss,
// so the reader still sees every value once and in order.
TEST(DistProcesses, TenPercentPacketLossLosesNothingAndReordersNothing) {
  const auto file =
      std::filesystem::temp_directory_path() / ("vsd_dist_lossy_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file)
      << "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
      << "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
      << "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40"
      << "</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
      << "<Internal><Test><XmitLossiness>100</XmitLossiness></Test></Internal></Domain></CycloneDDS>";
  const std::string peer = VSD_DIST_PEER;
  const std::string d = std::to_string(vsd_dist_test::fresh_domain());
  const std::string config = " --config file://" + file.string();
  const auto [rc, out] =
      run("timeout 120 " + peer + " writer " + d + " 2000" + config + " & W=$!; timeout 100 " + peer +
          " reader " + d + " 2000" + config + "; R=$?; wait $W; W=$?; [ $R -eq 0 ] && [ $W -eq 0 ]");
  std::filesystem::remove(file);
  if (out.find("creating the DDS domain") != std::string::npos)
    GTEST_SKIP() << "this Cyclone DDS has no Internal/Test/XmitLossiness: " << out;
  EXPECT_EQ(rc, 0) << out;
  EXPECT_THAT(out,
              testing::ContainsRegex("reader: synced at [0-9]+, then [0-9]+ values in order, final 2000"));
}

// Two network namespaces joined by a veth pair, netem loss, delay and reordering on both ends. Needs root,
// ip and tc; removes its namespaces whatever happens.
TEST(DistProcesses, NetworkNamespacesWithLossDelayAndReordering) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root (network namespaces)";
  if (run("command -v ip && command -v tc").first != 0) GTEST_SKIP() << "needs ip and tc (iproute2)";
  const std::string tag = std::to_string(::getpid() % 100000);
  const std::string ns1 = "vsdA" + tag, ns2 = "vsdB" + tag, v1 = "va" + tag, v2 = "vb" + tag;
  struct Cleanup {
    std::string a, b;
    ~Cleanup() { (void)run("ip netns del " + a + "; ip netns del " + b); }
  } cleanup{ns1, ns2};
  const auto [setup_rc, setup_out] =
      run("set -e; ip netns add " + ns1 + "; ip netns add " + ns2 + "; ip link add " + v1 +
          " type veth peer name " + v2 + "; ip link set " + v1 + " netns " + ns1 + "; ip link set " + v2 +
          " netns " + ns2 + "; ip -n " + ns1 + " addr add 10.231.0.1/24 dev " + v1 + "; ip -n " + ns2 +
          " addr add 10.231.0.2/24 dev " + v2 + "; ip -n " + ns1 + " link set " + v1 + " up; ip -n " + ns2 +
          " link set " + v2 + " up; ip -n " + ns1 + " link set lo up; ip -n " + ns2 + " link set lo up");
  if (setup_rc != 0) GTEST_SKIP() << "cannot make network namespaces here: " << setup_out;
  const auto [netem_rc, netem_out] =
      run("set -e; ip netns exec " + ns1 + " tc qdisc add dev " + v1 +
          " root netem delay 2ms 1ms loss 5% reorder 10% 50%; ip netns exec " + ns2 + " tc qdisc add dev " +
          v2 + " root netem delay 2ms 1ms loss 5% reorder 10% 50%");
  if (netem_rc != 0) {
    // Containers often lack the sch_netem kernel module: the namespaces and the veth pair are still tested.
    std::cout << "note: netem is not available here (" << netem_out
              << "); running across the namespaces without loss, delay and reordering\n";
    RecordProperty("netem", "unavailable");
  }
  const auto dir = std::filesystem::temp_directory_path() / ("vsd_dist_netns_" + tag);
  std::filesystem::create_directories(dir);
  auto config = [&](const std::string& dev, const std::string& peer_ip) {
    const auto file = dir / (dev + ".xml");
    std::ofstream(file) << "<CycloneDDS><Domain id=\"any\"><General><Interfaces><NetworkInterface name=\""
                        << dev
                        << "\"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
                        << "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"" << peer_ip
                        << "\"/></Peers></Discovery></Domain></CycloneDDS>";
    return "file://" + file.string();
  };
  const std::string peer = VSD_DIST_PEER;
  const std::string d = std::to_string(vsd_dist_test::fresh_domain());
  const auto [rc, out] = run(
      "timeout 120 ip netns exec " + ns1 + " " + peer + " writer " + d + " 2000 --config " +
      config(v1, "10.231.0.2") + " & W=$!; timeout 100 ip netns exec " + ns2 + " " + peer + " reader " + d +
      " 2000 --config " + config(v2, "10.231.0.1") + "; R=$?; wait $W; W=$?; [ $R -eq 0 ] && [ $W -eq 0 ]");
  std::filesystem::remove_all(dir);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_THAT(out,
              testing::ContainsRegex("reader: synced at [0-9]+, then [0-9]+ values in order, final 2000"));
}

}  // namespace
