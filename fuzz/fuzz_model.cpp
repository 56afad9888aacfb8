// libFuzzer target for one model reader (FUZZ_FORMAT: 0 OFF, 1 OBJ, 2 STL ascii, 3 STL
// binary, 4 PLY): parse_polygon_soup, then, for small soups, the CGAL-free checks and the
// feature extraction. A cf::Error is the expected answer to bad input; anything else
// (a crash, a sanitizer report, another exception, a leak) is a finding.

#include "mesh/mesh_detail.hpp"
#include "mesh/model_loader.hpp"

#include <cf/types.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#ifndef FUZZ_FORMAT
#error "define FUZZ_FORMAT"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  cf::tools::MeshFormat format = cf::tools::MeshFormat::kOff;
  switch (FUZZ_FORMAT) {
    case 0:
      format = cf::tools::MeshFormat::kOff;
      break;
    case 1:
      format = cf::tools::MeshFormat::kObj;
      break;
    case 2:
      format = cf::tools::MeshFormat::kStl;
      break;
    case 3: {
      // Binary STL: the input is the triangle records; the header and the count are made to
      // fit, so that every input takes the binary path.
      format = cf::tools::MeshFormat::kStl;
      const std::uint32_t n = static_cast<std::uint32_t>(size / 50);
      std::string b(80, 'b');
      char count[4];
      for (int i = 0; i < 4; ++i) count[i] = static_cast<char>((n >> (8 * i)) & 0xff);
      b.append(count, 4);
      b.append(bytes, 0, static_cast<std::size_t>(n) * 50);
      bytes = std::move(b);
      break;
    }
    default:
      format = cf::tools::MeshFormat::kPly;
      break;
  }
  try {
    const cf::tools::PolygonSoup soup = cf::tools::parse_polygon_soup(bytes, format, "fuzz");
    if (soup.points.size() <= 64 && soup.polygons.size() <= 64) {
      cf::tools::LoadOptions opt;
      opt.check_self_intersection = false;
      cf::tools::detail::check_soup(soup, "fuzz", opt);
      (void)cf::tools::detail::extract_features(soup, "fuzz", "fuzz", opt);
    }
  } catch (const cf::Error&) {
  }
  return 0;
}
