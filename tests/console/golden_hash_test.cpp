// The golden-hash determinism test: fixed scenarios run through `resecto run --headless` must end
// in the committed state hashes (tests/support/golden_hashes.h says what to do when one moves).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/console/run_resecto.h"
#include "tests/support/golden_hashes.h"

namespace resecto::testing {
namespace {

TEST(GoldenHash, FixedScenariosEndInTheCommittedHashes) {
  for (const GoldenRun& golden : kGoldenRuns) {
    const std::string arguments = std::string("run --headless ") + golden.arguments + " --json";
    const CommandOutput run = run_resecto(arguments);
    ASSERT_EQ(run.exit_code, 0) << arguments << ": " << run.err;
    const auto report = nlohmann::json::parse(run.out);
    EXPECT_EQ(report["metrics"]["cuts"].get<std::uint64_t>(), golden.cuts) << arguments;
    EXPECT_EQ(report["state_hash"].get<std::string>(), golden.state_hash)
        << "resecto " << arguments << ": the final state hash moved (see tests/support/golden_hashes.h)";
    EXPECT_EQ(report["hash_chain"].get<std::string>(), golden.hash_chain)
        << "resecto " << arguments << ": a collision step's hash moved (see tests/support/golden_hashes.h)";
  }
}

}  // namespace
}  // namespace resecto::testing
