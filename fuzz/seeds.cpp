// Writes seed corpora for the fuzzers: vsd_fuzz_seeds <snapshot dir> <transaction dir> <text dir>
#include <cstdio>
#include <filesystem>

#include "fuzz_model.hpp"
#include "vsd/io.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s <snapshot corpus dir> <transaction corpus dir> <text corpus dir>\n", argv[0]);
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
