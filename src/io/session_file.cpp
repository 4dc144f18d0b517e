// Either kind of session file, chosen by its `# format:` line. The formats themselves are
// ballbar_session_file.cpp and rtest_session_file.cpp over the strict reader (strict_reader.hpp).
#include <algorithm>

#include "rotacal/io/ballbar_file.hpp"
#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

AnySession read_session(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  // Sniff the format line from the first 4 kB only (a file without line ends stays bounded).
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::string line;
  for (std::size_t a = 0; a < head.size();) {
    const std::size_t nl = std::min(head.find('\n', a), head.size());
    line = head.substr(a, nl - a);
    if (!trim(line).empty()) break;
    a = nl + 1;
  }
  const std::string t = trim(line);
  in.clear();
  in.seekg(0);
  if (!in) {
    in = open_for_reading(path);  // not seekable: open again
  }
  if (t.find(kRtestFormat) != std::string::npos) return parse_rtest(in, path);
  // Anything but a plain-text first line (binary data, no line end in 4 kB, not UTF-8) gets
  // the ballbar reader's precise message (line, column, byte).
  const bool plain = head.find('\n') != std::string::npos &&
                     std::all_of(line.begin(), line.end(), [](char c) {
                       const unsigned char u = static_cast<unsigned char>(c);
                       return (u >= 0x20 && u < 0x7F) || u == '\t' || u == '\r';
                     });
  if (t.find(kBallbarFormat) != std::string::npos || t.empty() || !plain) return parse_ballbar(in, path);
  throw ParseError(path, 1, 1, std::string("first line must be '# format: ") + kBallbarFormat + "' or '# format: " +
                                   kRtestFormat + "', got '" + excerpt(t) + "'");
}

}  // namespace rotacal
