// SPDX-License-Identifier: BSD-3-Clause
// Either kind of session file, chosen by its `# format:` line. The formats themselves are
// ballbar_session_file.cpp and rtest_session_file.cpp over the strict reader (strict_reader.hpp);
// probe_file.cpp reads rotacal-probe/1 and uses the same sniffing.
#include <algorithm>

#include "rotacal/io/ballbar_file.hpp"
#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

FormatLine io_detail::sniff_format_line(std::ifstream& in, const std::string& path) {
  // The format line from the first 4 kB only (a file without line ends stays bounded).
  FormatLine out;
  out.head.assign(4096, '\0');
  in.read(out.head.data(), static_cast<std::streamsize>(out.head.size()));
  out.head.resize(static_cast<std::size_t>(in.gcount()));
  for (std::size_t a = 0; a < out.head.size();) {
    const std::size_t nl = std::min(out.head.find('\n', a), out.head.size());
    out.line = out.head.substr(a, nl - a);
    if (!trim(out.line).empty()) break;
    a = nl + 1;
  }
  in.clear();
  in.seekg(0);
  if (!in) in = open_for_reading(path);  // not seekable: open again
  return out;
}

AnySession read_session(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  return read_sniffed_session(in, path, sniff_format_line(in, path));
}

AnySession io_detail::read_sniffed_session(std::ifstream& in, const std::string& path,
                                           const FormatLine& sniffed) {
  const std::string &head = sniffed.head, &line = sniffed.line;
  const std::string t = trim(line);
  if (t.find(kRtestFormat) != std::string::npos) return parse_rtest(in, path);
  // Anything but a plain-text first line (binary data, no line end in 4 kB, not UTF-8) gets
  // the ballbar reader's precise message (line, column, byte).
  const bool plain =
      head.find('\n') != std::string::npos && std::all_of(line.begin(), line.end(), [](char c) {
        const unsigned char u = static_cast<unsigned char>(c);
        return (u >= 0x20 && u < 0x7F) || u == '\t' || u == '\r';
      });
  if (t.find(kBallbarFormat) != std::string::npos || t.empty() || !plain)
    return parse_ballbar(in, path);
  throw ParseError(path, 1, 1,
                   std::string("first line must be '# format: ") + kBallbarFormat +
                       "' or '# format: " + kRtestFormat + "', got '" + excerpt(t) + "'");
}

}  // namespace rotacal
