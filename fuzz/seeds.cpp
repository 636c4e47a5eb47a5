// Writes seed corpora for the fuzzers: vsd_fuzz_seeds <snapshot dir> <transaction dir> <text dir>
#include <cstdio>
#include <filesystem>

#include "fuzz_model.hpp"
#include "vsd/io.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <snapshot corpus dir> <transaction corpus dir> <text corpus dir>\n",
                 argv[0]);
    return 2;
  }
  const std::filesystem::path snapshots = argv[1], bundles = argv[2], texts = argv[3];
  std::filesystem::create_directories(snapshots);
  std::filesystem::create_directories(bundles);
  std::filesystem::create_directories(texts);
  vsd::Environment env;
  vsd::SimState& s = env.main_state();
  fuzz::build(s);
  vsd::io::write_file_atomically(snapshots / "model.vsds", vsd::io::save_bytes(s));
  vsd::io::write_file_atomically(snapshots / "subtree.vsds",
                                 vsd::io::save_bytes(*s.database().children()[0]));
  vsd::io::write_file_atomically(texts / "model.json", vsd::io::save_bytes(s, vsd::io::Format::Text));
  vsd::io::write_file_atomically(texts / "subtree.json",
                                 vsd::io::save_bytes(*s.database().children()[0], vsd::io::Format::Text));
  // Files that carry run-time types (version 2): an enum, flags and a struct used by a run-time class.
  {
    const vsd::MetaType& shade = vsd::EnumBuilder("FzShade").value("Dark", 0).value("Light", 7).define();
    const vsd::MetaType& access =
        vsd::EnumBuilder("FzAccess", vsd::TypeKind::Flags).value("Read", 1).value("Write", 2).define();
    const vsd::MetaType& tag =
        vsd::StructBuilder("FzTag").field<std::string>("label").field("shade", shade).define();
    const vsd::MetaInstance& marker = vsd::ClassBuilder("FzMarker", vsd::Node::static_meta())
                                          .property("tag", tag)
                                          .property("tags", vsd::Registry::global().get_type("vector<FzTag>"))
                                          .property("access", access)
                                          .define();
    vsd::Environment typed;
    auto& m = static_cast<vsd::Node&>(typed.main_state().create(marker));
    m.set("tag", vsd::Value::from_text(tag, "{\"label\": \"a\", \"shade\": \"Light\"}"));
    m.set("tags",
          vsd::Value::from_text(vsd::Registry::global().get_type("vector<FzTag>"), "[{\"label\": \"b\"}]"));
    typed.main_state().database().add_child(m);
    vsd::io::write_file_atomically(snapshots / "types.vsds", vsd::io::save_bytes(typed.main_state()));
    vsd::io::write_file_atomically(texts / "types.json",
                                   vsd::io::save_bytes(typed.main_state(), vsd::io::Format::Text));
  }
  // Bundles that fit the fuzzer's base state (same classes, same ids: a fresh Environment builds it).
  vsd::Environment base;
  vsd::SimState& b = base.main_state();
  fuzz::build(b);
  b.start_recording();
  auto* cell = b.database().children()[0];
  auto* r = static_cast<fuzz::FzRobot*>(cell->children()[0]);
  r->set_speed(9);
  r->set_joints({1, 2, 3});
  auto& extra = b.create<fuzz::FzRobot>();
  cell->add_child(extra);
  extra.set_target(r);
  vsd::io::write_file_atomically(bundles / "edits.vsdt", b.take_recording().bytes());
  b.destroy(*r);
  vsd::io::write_file_atomically(bundles / "delete.vsdt", b.take_recording().bytes());
  std::printf("seeds written to %s, %s and %s\n", snapshots.c_str(), bundles.c_str(), texts.c_str());
  return 0;
}
