#include "rtcore/tissue/stepped_nodes.h"

#include "rtcore/concurrency/loop_helper.h"

namespace resecto {

void SteppedNodes::reserve(std::size_t node_capacity, std::size_t nodes_per_chunk) {
  // Every other group listed makes the most spans; a chunk's end can split one more.
  const std::size_t groups = chunks_covering(node_capacity, kGroup);
  const std::size_t chunks = chunks_covering(node_capacity, nodes_per_chunk);
  spans_.reserve(groups / 2 + 1 + chunks);
  chunk_first_.reserve(chunks + 2);
}

}  // namespace resecto
