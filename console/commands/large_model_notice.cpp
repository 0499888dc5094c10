#include "console/commands/large_model_notice.h"

#include <cstdio>

namespace resecto::cli {

void note_large_model(std::size_t triangles, const char* what) {
  if (triangles <= kLargeModelTriangles) return;
  // The figures are a 2-core Zen 5 guest's (benchmarks/results, session 31): time grows faster than
  // the count, memory about 8.5 KB a triangle.
  std::fprintf(stderr,
               "note: building %s %zu surface triangles takes a while: about 30 s and 2.6 GB at 300,000, 160 s and 8.5 GB at "
               "1,000,000 on a 2-core machine (Ctrl-C ends it at once)\n",
               what, triangles);
}

}  // namespace resecto::cli
