#pragma once
// The live view's page (monitor/web/*.html, *.js, *.css), embedded in the binary at build time by
// monitor/web/embed.cmake, so that marsala-monitor serve needs no files beside it.

#include <string>
#include <vector>

namespace marsala::monitor {

/// One file of the page: its name (e.g. "index.html") and its bytes.
struct WebAsset {
  const char* name;
  std::string body;
};

/// The page's files, in the order monitor/CMakeLists.txt lists them.
const std::vector<WebAsset>& web_assets();

}  // namespace marsala::monitor
