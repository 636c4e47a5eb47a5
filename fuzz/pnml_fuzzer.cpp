// Fuzzes the PNML reader (pugixml underneath) and the nets it accepts: any input must end in a net or a
// vsd::Error, never a crash, a hang or a sanitizer report. An accepted net must survive the round trips
// the tool offers: PNML written and read back is the same net, and SOML++ written and read back has the
// same places, markings and arcs (ids may be renamed).
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "vsd/core/error.hpp"
#include "vsd/analysis.hpp"

namespace {

namespace an = vsd::analysis;

void require(bool ok) {
  if (!ok) std::abort();
}

bool same_structure(const an::PtNet& a, const an::PtNet& b) {
  if (a.place_count() != b.place_count() || a.transition_count() != b.transition_count()) return false;
  if (a.initial_marking() != b.initial_marking()) return false;
  auto arcs = [](const std::vector<an::ArcRef>& v) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (const auto& x : v) out.emplace_back(x.place, x.weight);
    return out;
  };
  for (std::size_t t = 0; t < a.transition_count(); ++t) {
    const auto &x = a.transitions()[t], &y = b.transitions()[t];
    if (arcs(x.inputs) != arcs(y.inputs) || arcs(x.outputs) != arcs(y.outputs) ||
        arcs(x.inhibitors) != arcs(y.inhibitors))
      return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  an::PnmlImport imported;
  try {
    imported = an::read_pnml(text, "fuzz.pnml");
  } catch (const vsd::Error&) {
    return 0;  // refused with a message: fine
  }
  const an::PnmlImport again = an::read_pnml(an::write_pnml(imported.net), "written.pnml");
  require(again.net == imported.net);
  const an::SomlNetImport soml = an::read_soml_net(an::write_soml(imported.net), "written.soml");
  require(same_structure(soml.net, imported.net));
  return 0;
}
