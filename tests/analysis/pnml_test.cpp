// PNML import and export: the MCC nets, round trips, and every kind of bad input with its line:col.
#include "vsd/analysis/pnml.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "vsd/core/error.hpp"
#include "vsd/analysis/explorer.hpp"
#include "vsd/analysis/soml_net.hpp"

namespace an = vsd::analysis;
using an::PtNet;

namespace {

const std::string kData = VSD_ANALYSIS_TEST_DATA_DIR;
const char* const kModels[] = {
    "ResAllocation-PT-R002C002", "Eratosthenes-PT-010", "TokenRing-PT-005", "Philosophers-PT-000005",
    "SharedMemory-PT-000005",    "FMS-PT-00002",        "Dekker-PT-010",    "Peterson-PT-2"};

std::string wrap(const std::string& page_content,
                 const std::string& type = "http://www.pnml.org/version-2009/grammar/ptnet") {
  return "<?xml version=\"1.0\"?>\n<pnml xmlns=\"http://www.pnml.org/version-2009/grammar/pnml\">\n<net "
         "id=\"n\" type=\"" +
         type + "\">\n<page id=\"pg\">\n" + page_content + "</page>\n</net>\n</pnml>\n";
}

std::string pnml_error_of(const std::string& text) {
  try {
    an::read_pnml(text, "t.pnml");
  } catch (const vsd::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(Pnml, MccNetsHaveTheCountsOfExpectedTsv) {
  std::ifstream in(kData + "/expected.tsv");
  std::string model, header;
  std::getline(in, header);
  std::size_t places = 0, transitions = 0, arcs = 0, rows = 0;
  std::string rest;
  while (in >> model >> places >> transitions >> arcs) {
    std::getline(in, rest);
    SCOPED_TRACE(model);
    const an::PnmlImport imp = an::read_pnml_file(kData + "/" + model + ".pnml");
    EXPECT_EQ(imp.net.id(), model);
    EXPECT_EQ(imp.net.place_count(), places);
    EXPECT_EQ(imp.net.transition_count(), transitions);
    EXPECT_EQ(imp.net.arc_count(), arcs);
    EXPECT_FALSE(imp.net.has_inhibitors());
    ++rows;
  }
  EXPECT_EQ(rows, 8u);
}

TEST(Pnml, NamesIdsMarkingsAndWeightsAreKept) {
  const an::PnmlImport imp = an::read_pnml_file(kData + "/FMS-PT-00002.pnml");
  const PtNet& net = imp.net;
  EXPECT_EQ(net.name(), "FMS-PT-00002");
  const auto p = net.find_place("P1");
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(net.places()[*p].name, "P1");
  EXPECT_EQ(net.places()[*p].initial, 2u);
  EXPECT_TRUE(net.find_transition("tP1").has_value());
  EXPECT_FALSE(net.find_place("tP1").has_value());
  // The arc cId1097071320973282518114 goes P1 -> tP1.
  const auto& t = net.transitions()[*net.find_transition("tP1")];
  ASSERT_EQ(t.inputs.size(), 1u);
  EXPECT_EQ(t.inputs[0].place, *p);
  EXPECT_EQ(t.inputs[0].id, "cId1097071320973282518114");
  EXPECT_EQ(t.inputs[0].weight, 1u);
}

TEST(Pnml, ToolSpecificBlocksAreSkippedWithANote) {
  const an::PnmlImport imp = an::read_pnml_file(kData + "/Philosophers-PT-000005.pnml");
  ASSERT_EQ(imp.notes.size(), 2u);  // the NUPN block, and the layout (<graphics>) of 110 elements
  EXPECT_NE(imp.notes[0].find("Philosophers-PT-000005.pnml:"), std::string::npos);
  EXPECT_NE(imp.notes[0].find("skipped <toolspecific tool=\"nupn\" version=\"1.1\">"), std::string::npos);
  EXPECT_NE(imp.notes[1].find("skipped <graphics> (layout) of 110 element(s)"), std::string::npos)
      << imp.notes[1];
  // The position is the '<' of the element.
  std::ifstream in(kData + "/Philosophers-PT-000005.pnml");
  std::string line;
  int n = 0, found = 0;
  std::size_t col = 0;
  while (std::getline(in, line)) {
    ++n;
    if (const auto c = line.find("<toolspecific"); c != std::string::npos) {
      found = n;
      col = c + 1;
    }
  }
  EXPECT_NE(imp.notes[0].find(":" + std::to_string(found) + ":" + std::to_string(col) + ":"),
            std::string::npos)
      << imp.notes[0];
}

TEST(Pnml, UnknownElementsAndGraphicsAreReported) {
  const std::string text = wrap(
      "<place id=\"p\"><name><text>P</text><graphics><offset x=\"0\" y=\"0\"/></graphics></name>"
      "<graphics><position x=\"1\" y=\"2\"/></graphics><capacity><text>3</text></capacity></place>\n"
      "<transition id=\"t\"/>\n<arc id=\"a\" source=\"p\" target=\"t\"/>\n");
  const an::PnmlImport imp = an::read_pnml(text, "u.pnml");
  ASSERT_EQ(imp.notes.size(), 2u);
  EXPECT_NE(imp.notes[0].find("u.pnml:5:"), std::string::npos) << imp.notes[0];
  EXPECT_NE(imp.notes[0].find("skipped unknown element <capacity>"), std::string::npos);
  EXPECT_NE(imp.notes[1].find("<graphics>"), std::string::npos) << imp.notes[1];
  EXPECT_EQ(imp.net.places()[0].name, "P");
}

TEST(Pnml, MalformedXmlGivesLineAndColumn) {
  // Line 5 closes </net> while <place> is open.
  const std::string text =
      "<?xml version=\"1.0\"?>\n<pnml>\n<net id=\"n\" "
      "type=\"http://www.pnml.org/version-2009/grammar/ptnet\">\n"
      "  <page id=\"g\"><place id=\"p\">\n</net>\n</pnml>\n";
  const std::string e = pnml_error_of(text);
  EXPECT_EQ(e.rfind("t.pnml:5:", 0), 0u) << e;
  EXPECT_NE(e.find("malformed XML"), std::string::npos) << e;
  const std::string e2 = pnml_error_of("<pnml><net id=\"x\" type=\"y\"");
  EXPECT_EQ(e2.rfind("t.pnml:1:", 0), 0u) << e2;
  EXPECT_NE(pnml_error_of("").find("t.pnml:1:1:"), std::string::npos);
}

TEST(Pnml, UnsupportedNetTypesAreRefused) {
  const std::string e = pnml_error_of(wrap("", "http://www.pnml.org/version-2009/grammar/symmetricnet"));
  EXPECT_EQ(e.rfind("t.pnml:3:1:", 0), 0u) << e;
  EXPECT_NE(e.find("symmetric net"), std::string::npos) << e;
  EXPECT_NE(e.find("not supported"), std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("", "http://www.pnml.org/version-2009/grammar/highlevelnet")).find("high-level"),
            std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("", "")).find("net type '' is not supported"), std::string::npos);
}

TEST(Pnml, StructuralErrorsNameTheElementAndPosition) {
  EXPECT_NE(
      pnml_error_of(
          wrap("<place id=\"p\"/>\n<transition id=\"t\"/>\n<arc id=\"a\" source=\"p\" target=\"nope\"/>\n"))
          .find("t.pnml:7:1: arc 'a' has unknown target 'nope'"),
      std::string::npos);
  EXPECT_NE(
      pnml_error_of(wrap("<place id=\"p\"/>\n<place id=\"q\"/>\n<arc id=\"a\" source=\"p\" target=\"q\"/>\n"))
          .find("joins two places"),
      std::string::npos);
  EXPECT_NE(
      pnml_error_of(wrap("<place id=\"p\"/>\n<transition id=\"p\"/>\n")).find("t.pnml:6:1: duplicate id 'p'"),
      std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place id=\"p\"><initialMarking><text>-1</text></initialMarking></place>\n"))
                .find("initial marking '-1' is not an integer"),
            std::string::npos);
  EXPECT_NE(
      pnml_error_of(wrap("<place id=\"p\"><initialMarking><text>9999999999</text></initialMarking></place>\n"))
          .find("is not an integer in [0, 2^32-1]"),
      std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place id=\"p\"/><transition id=\"t\"/><arc id=\"a\" source=\"p\" target=\"t\">"
                          "<inscription><text>0</text></inscription></arc>\n"))
                .find("arc weight is 0"),
            std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place/>\n")).find("<place> without an id"), std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place id=\"p\"/><transition id=\"t\"/><arc id=\"a\" source=\"t\" target=\"p\">"
                          "<type value=\"inhibitor\"/></arc>\n"))
                .find("must go from a place to a transition"),
            std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place id=\"p\"/><transition id=\"t\"/><arc id=\"a\" source=\"p\" target=\"t\">"
                          "<type value=\"reset\"/></arc>\n"))
                .find("arc type 'reset' is not supported"),
            std::string::npos);
  EXPECT_NE(pnml_error_of("<foo/>").find("expected <pnml>"), std::string::npos);
  EXPECT_NE(pnml_error_of("<pnml/>").find("holds no <net>"), std::string::npos);
  EXPECT_NE(pnml_error_of("<pnml><net id=\"a\" type=\"x\"/><net id=\"b\" type=\"x\"/></pnml>").find("2 nets"),
            std::string::npos);
  EXPECT_THROW(an::read_pnml_file(kData + "/does-not-exist.pnml"), vsd::Error);
}

TEST(Pnml, ReferenceNodesNestedPagesAndParallelArcs) {
  const std::string text = wrap(
      "<place id=\"p\"><initialMarking><text>2</text></initialMarking></place>\n"
      "<page id=\"inner\"><referencePlace id=\"rp\" ref=\"p\"/><referencePlace id=\"rp2\" ref=\"rp\"/>"
      "<transition id=\"t\"/><arc id=\"a1\" source=\"rp2\" target=\"t\"/></page>\n"
      "<arc id=\"a2\" source=\"p\" target=\"t\"/>\n");
  const an::PnmlImport imp = an::read_pnml(text);
  ASSERT_EQ(imp.net.transition_count(), 1u);
  ASSERT_EQ(imp.net.transitions()[0].inputs.size(), 1u);
  EXPECT_EQ(imp.net.transitions()[0].inputs[0].weight, 2u);  // two parallel arcs of weight 1
  EXPECT_EQ(imp.net.transitions()[0].inputs[0].id, "a1");
  ASSERT_EQ(imp.notes.size(), 1u);
  EXPECT_NE(imp.notes[0].find("arc 'a2' is parallel"), std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<referencePlace id=\"r\" ref=\"nowhere\"/>\n")).find("reference to unknown place"),
            std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<referencePlace id=\"r\" ref=\"s\"/><referencePlace id=\"s\" ref=\"r\"/>\n"))
                .find("reference cycle"),
            std::string::npos);
}

TEST(Pnml, RoundTripOfTheMccNets) {
  for (const char* model : kModels) {
    SCOPED_TRACE(model);
    const an::PnmlImport first = an::read_pnml_file(kData + "/" + model + ".pnml");
    const std::string written = an::write_pnml(first.net);
    const an::PnmlImport second = an::read_pnml(written, "written");
    EXPECT_TRUE(second.notes.empty());
    EXPECT_EQ(second.net, first.net);  // ids, names, markings, arcs with ids and weights
    EXPECT_EQ(an::write_pnml(second.net), written);
  }
}

TEST(Pnml, RoundTripKeepsWeightsAndInhibitorsAndMakesUpMissingArcIds) {
  PtNet net("rt", "round trip");
  const auto p = net.add_place("p", "the place", 5);
  const auto q = net.add_place("q");
  const auto t = net.add_transition("t", "fire");
  net.add_input(t, p, 3, "in");
  net.add_output(t, q, 2);     // no id: export makes one up
  net.add_inhibitor(t, q, 4);  // also none
  const std::string text = an::write_pnml(net);
  EXPECT_NE(text.find("<type value=\"inhibitor\""), std::string::npos);
  const an::PnmlImport back = an::read_pnml(text);
  const PtNet& n2 = back.net;
  EXPECT_EQ(n2.id(), "rt");
  EXPECT_EQ(n2.name(), "round trip");
  EXPECT_EQ(n2.places()[0].name, "the place");
  EXPECT_EQ(n2.places()[0].initial, 5u);
  EXPECT_EQ(n2.transitions()[0].name, "fire");
  EXPECT_EQ(n2.transitions()[0].inputs, (std::vector<an::ArcRef>{{p, 3, "in"}}));
  ASSERT_EQ(n2.transitions()[0].outputs.size(), 1u);
  EXPECT_EQ(n2.transitions()[0].outputs[0].weight, 2u);
  EXPECT_FALSE(n2.transitions()[0].outputs[0].id.empty());
  ASSERT_EQ(n2.transitions()[0].inhibitors.size(), 1u);
  EXPECT_EQ(n2.transitions()[0].inhibitors[0].weight, 4u);
  EXPECT_NE(n2.transitions()[0].outputs[0].id, n2.transitions()[0].inhibitors[0].id);
  // Same state space both ways.
  an::ExploreOptions o;
  o.progress = an::ExploreOptions::Progress::never;
  const auto r1 = an::explore(net, o);
  const auto r2 = an::explore(n2, o);
  EXPECT_EQ(r1.states, r2.states);
  EXPECT_EQ(r1.edges, r2.edges);
  EXPECT_EQ(r1.deadlock, r2.deadlock);
}

TEST(Pnml, WriteAndReadFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("vsd_pnml_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const PtNet net = an::read_pnml_file(kData + "/TokenRing-PT-005.pnml").net;
  an::write_pnml_file(net, dir / "ring.pnml");
  EXPECT_EQ(an::read_pnml_file(dir / "ring.pnml").net, net);
  EXPECT_THROW(an::write_pnml_file(net, dir / "missing-dir" / "x.pnml"), vsd::Error);
  std::filesystem::remove_all(dir);
}

TEST(Pnml, PagesNestedToAnyDepthAreReadWithoutRecursion) {
  // 50,000 nested pages overflowed the reader's recursion (SIGSEGV); pugixml itself parses iteratively.
  constexpr int kDepth = 100'000;
  std::string pages;
  pages.reserve(kDepth * 24);
  for (int i = 0; i < kDepth; ++i) pages += "<page id=\"q" + std::to_string(i) + "\">";
  pages += "<place id=\"deep\"/><transition id=\"t\"/><arc id=\"a\" source=\"deep\" target=\"t\"/>";
  for (int i = 0; i < kDepth; ++i) pages += "</page>";
  const an::PnmlImport imp = an::read_pnml(wrap(pages), "deep.pnml");
  ASSERT_TRUE(imp.net.find_place("deep").has_value());
  EXPECT_EQ(imp.net.transitions().at(0).inputs.size(), 1u);
  // Other elements nested as deep are skipped as one (a note), not walked.
  const std::string deep_unknown = std::string("<place id=\"p\"/>") + [&] {
    std::string x;
    for (int i = 0; i < kDepth; ++i) x += "<x>";
    for (int i = 0; i < kDepth; ++i) x += "</x>";
    return x;
  }();
  const an::PnmlImport unknown = an::read_pnml(wrap(deep_unknown), "deep.pnml");
  ASSERT_EQ(unknown.notes.size(), 1u);
  EXPECT_NE(unknown.notes[0].find("skipped unknown element <x>"), std::string::npos) << unknown.notes[0];
}

TEST(Pnml, ReferenceChainsResolveInLinearTimeAndCyclesAreNamed) {
  // Each reference used to follow its chain to the end: 20,000 chained references took 10.6 s (this chain
  // would take minutes); each chain is now followed once.
  constexpr int kChain = 50'000;
  std::string refs = "<place id=\"p\"/><transition id=\"t\"/><referencePlace id=\"r0\" ref=\"p\"/>";
  for (int i = 1; i < kChain; ++i)
    refs += "<referencePlace id=\"r" + std::to_string(i) + "\" ref=\"r" + std::to_string(i - 1) + "\"/>";
  refs += "<arc id=\"a\" source=\"r" + std::to_string(kChain - 1) + "\" target=\"t\"/>";
  const an::PnmlImport imp = an::read_pnml(wrap(refs));
  ASSERT_EQ(imp.net.transitions().at(0).inputs.size(), 1u);
  EXPECT_EQ(imp.net.transitions()[0].inputs[0].place, *imp.net.find_place("p"));
  // A long cycle: named with its length and its first references, at the reference that closes it.
  std::string cycle;
  for (int i = 0; i < kChain; ++i)
    cycle += "<referencePlace id=\"c" + std::to_string(i) + "\" ref=\"c" + std::to_string((i + 1) % kChain) +
             "\"/>";
  const std::string e = pnml_error_of(wrap(cycle));
  EXPECT_NE(e.find("t.pnml:5:1: reference cycle of 50000 reference(s): 'c0' -> 'c1' -> "), std::string::npos)
      << e.substr(0, 300);
  EXPECT_NE(e.find("'c9' -> ... -> 'c0'"), std::string::npos) << e.substr(0, 300);
  EXPECT_NE(pnml_error_of(wrap("<referencePlace id=\"s\" ref=\"s\"/>")).find("reference cycle of 1 reference(s): 's' -> 's'"),
            std::string::npos);
  EXPECT_NE(pnml_error_of(wrap("<place id=\"p\"/><referencePlace id=\"s\"/>")).find("<referencePlace> without a ref"),
            std::string::npos);
}

TEST(Pnml, ATransitionOfManyArcsIsBuiltInLinearTime) {
  // Merging parallel arcs searched the transition's arcs: n arcs cost O(n^2).
  constexpr int kArcs = 100'000;
  std::string text = "<transition id=\"t\"/>";
  for (int i = 0; i < kArcs; ++i) {
    const std::string n = std::to_string(i);
    text += "<place id=\"p" + n + "\"/><arc id=\"a" + n + "\" source=\"p" + n + "\" target=\"t\"/><arc id=\"b" + n +
            "\" source=\"t\" target=\"p" + n + "\"/>";
  }
  text += "<arc id=\"again\" source=\"p7\" target=\"t\"><inscription><text>2</text></inscription></arc>";
  const an::PnmlImport imp = an::read_pnml(wrap(text));
  const an::Transition& t = imp.net.transitions().at(0);
  EXPECT_EQ(t.inputs.size(), std::size_t{kArcs});
  EXPECT_EQ(t.outputs.size(), std::size_t{kArcs});
  EXPECT_EQ(t.inputs[7].weight, 3u);  // merged with the parallel arc
  ASSERT_EQ(imp.notes.size(), 1u);
  EXPECT_NE(imp.notes[0].find("arc 'again' is parallel"), std::string::npos);
}

TEST(Pnml, ADirectoryIsNotAFileAndStreamsAndPipesAreRead) {
  const auto dir = std::filesystem::temp_directory_path() / ("vsd_pnml_dir_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // A directory opened as a file reads as nothing: it used to be analysed as an empty net.
  auto error_of = [](auto&& read) -> std::string {
    try {
      read();
    } catch (const vsd::Error& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error_of([&] { (void)an::read_pnml_file(dir); }), dir.string() + ": is a directory, not a file");
  EXPECT_EQ(error_of([&] { (void)an::read_soml_net_file(dir); }), dir.string() + ": is a directory, not a file");
  EXPECT_NE(error_of([&] { (void)an::read_pnml_file(dir / "missing.pnml"); }).find("cannot open the file for reading (No such file or directory)"),
            std::string::npos);
  // A stream (standard input, say) and a named pipe.
  const std::string text = wrap("<place id=\"p\"><initialMarking><text>3</text></initialMarking></place>\n");
  std::istringstream in(text);
  EXPECT_EQ(an::read_pnml(in, "<stdin>").net.places().at(0).initial, 3u);
  std::istringstream bad("<pnml>");
  EXPECT_NE(error_of([&] { (void)an::read_pnml(bad, "<stdin>"); }).find("<stdin>:1:"), std::string::npos);
  std::istringstream script("place a = 2; place b; transition t {} arrow a -> t; arrow t -> b;");
  EXPECT_EQ(an::read_soml_net(script, "<stdin>").net.place_count(), 2u);
  const auto fifo = dir / "net.pnml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] { std::ofstream(fifo) << text; });
  const an::PnmlImport piped = an::read_pnml_file(fifo);
  writer.join();
  EXPECT_EQ(piped.net.places().at(0).initial, 3u);
  std::filesystem::remove_all(dir);
}

}  // namespace
