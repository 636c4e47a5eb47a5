// The nets' pictures for docs/workcell.md (examples/workcell/two_robots/net_picture.hpp): DOT made from the
// checked scripts. Graphviz is not needed here (scripts/net-pictures.sh renders the DOT).
#include "net_picture.hpp"

#include <gtest/gtest.h>

#include "vsd/core/error.hpp"

namespace {

TEST(NetPicture, MultiRobotControlShowsObjectsPlacesTransitionsAndCommunicationArrows) {
  const std::string dot = vsd_workcell::net_dot(VSD_CELL_ROBOTS);
  EXPECT_EQ(dot.rfind("digraph \"multi_robot_control.soml\" {", 0), 0u) << dot.substr(0, 80);
  for (const char* s : {"subgraph \"cluster_a\"", "subgraph \"cluster_b\"", "subgraph \"cluster_zone\"",
                        "\"zone.free\" [shape=circle, fixedsize=false, label=\"free\\n*\"]",
                        "\"a.fetch\" [shape=box", "label=\"fetch\\nσ γ\"",
                        "\"zone.free\" -> \"a.enter\" [style=dashed, ]", "\"a.idle\" -> \"a.fetch\" []",
                        "\"b.exit\" -> \"zone.free\" [style=dashed, ]"})
    EXPECT_NE(dot.find(s), std::string::npos) << s;
  EXPECT_EQ(dot.back(), '\n');
}

TEST(NetPicture, MetaControlShowsObjectPlacesAndWhereJobsStart) {
  const std::string dot = vsd_workcell::net_dot(VSD_CELL_META);
  for (const char* s : {"subgraph \"cluster_meta\"", "label=\"arrived\\nplace<Job>\"", "\"new Job\" -> \"meta.arrived\"",
                        "\"meta.board_free\" -> \"meta.post\" []", "\"meta.divert\" [shape=box"})
    EXPECT_NE(dot.find(s), std::string::npos) << s;
}

TEST(NetPicture, AScriptThatDoesNotCheckIsAnError) {
  EXPECT_THROW(vsd_workcell::net_dot("/nonexistent/net.soml"), vsd::Error);
}

}  // namespace
