// The console's core session without a window: its lockstep run is the headless batch run tick for
// tick (same hash at every collision step); pause holds the tick, steps run exactly as many ticks as
// asked; a parameter change applies at the tick it was stamped for when the core is paused there,
// and the hashes differ from that tick on.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "console/headless/headless_run.h"
#include "console/live/core_session.h"

namespace resecto {
namespace {

CoreSessionOptions lockstep_demo() {
  CoreSessionOptions options;
  Result<Procedure> demo = builtin_procedure("demo");
  EXPECT_TRUE(demo);
  options.device.procedure = *demo;
  options.lockstep = true;
  options.simulation.prostate_triangles = 1296;
  options.realtime_priority = false;  // tests share the machine
  return options;
}

/// Polls the newest frame until `done` holds (or ten seconds pass); returns the frame it held for.
template <class Done>
CoreStatus wait_for(CoreSession& session, Done done) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < give_up) {
    session.frames().update();
    const CoreStatus& status = session.frames().read_slot().status;
    if (done(status)) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ADD_FAILURE() << "the core never got there";
  return session.frames().read_slot().status;
}

std::vector<std::uint64_t> headless_hashes(std::uint64_t ticks) {
  HeadlessOptions options;
  options.procedure = *builtin_procedure("demo");
  options.simulation.prostate_triangles = 1296;
  options.seconds = static_cast<double>(ticks) / 960.0;
  Result<HeadlessResult> run = run_headless(options);
  EXPECT_TRUE(run);
  return run ? run->collision_hashes : std::vector<std::uint64_t>{};
}

TEST(CoreSession, PauseHoldsAndStepsRunExactlyTheTicksAsked) {
  Result<std::unique_ptr<CoreSession>> created = CoreSession::create(lockstep_demo());
  ASSERT_TRUE(created);
  CoreSession& session = **created;
  session.start();
  wait_for(session, [](const CoreStatus& s) { return s.next_tick > 200; });
  ASSERT_TRUE(session.send({CoreControlKind::kPause, {}, 0, 0, 1.0, {}}));
  const CoreStatus paused = wait_for(session, [](const CoreStatus& s) { return s.paused; });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(session.next_tick(), paused.next_tick) << "a paused core runs no tick";
  ASSERT_TRUE(session.send({CoreControlKind::kStep, {}, 0, 1000, 1.0, {}}));
  const CoreStatus stepped = wait_for(session, [&](const CoreStatus& s) { return s.next_tick >= paused.next_tick + 1000 && s.pending_steps == 0; });
  EXPECT_EQ(stepped.next_tick, paused.next_tick + 1000);
  EXPECT_TRUE(stepped.paused);
  session.stop();
  EXPECT_EQ(session.simulation().tick(), paused.next_tick + 1000);
}

// The console's recording grows in PATH.partial, which its panel shows the size of, and replaces an
// older recording at PATH only when stopped: a crash or a full disk left the old one truncated (audit 7, F2).
TEST(CoreSession, ARecordingReplacesTheFileAtItsPathOnlyWhenStopped) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "resecto_core_session_record";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::filesystem::path path = dir / "session.rsrec", partial = dir / "session.rsrec.partial";
  { std::ofstream(path) << "the old recording"; }
  Result<std::unique_ptr<CoreSession>> created = CoreSession::create(lockstep_demo());
  ASSERT_TRUE(created);
  CoreSession& session = **created;
  session.start();
  CoreControl record{CoreControlKind::kRecordStart, {}, 0, 0, 1.0, path.string()};
  ASSERT_TRUE(session.send(record));
  const CoreStatus recording =
      wait_for(session, [](const CoreStatus& s) { return s.recording && s.next_tick > s.recording_start_tick + 200; });
  EXPECT_EQ(std::string(recording.recording_partial_path.data()), partial.string());
  EXPECT_TRUE(std::filesystem::exists(partial));
  {
    std::ifstream in(path);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "the old recording");
  }
  ASSERT_TRUE(session.send({CoreControlKind::kRecordStop, {}, 0, 0, 1.0, {}}));
  const CoreStatus stopped = wait_for(session, [](const CoreStatus& s) { return s.recordings_finished > 0; });
  session.stop();
  EXPECT_EQ(stopped.recording_message[0], '\0') << stopped.recording_message.data();
  EXPECT_FALSE(std::filesystem::exists(partial));
  EXPECT_GT(std::filesystem::file_size(path), 1000u);
}

TEST(CoreSession, APausedCoreLeavesThePhysicsHelperAsleep) {
  // The scheduler wakes the physics helper ahead of every tick; for a tick that will not step it
  // must not, or the helper spins through it at the core's priority (once it outlived the run and,
  // with two consoles on two processors, held the collision thread from ever being joined).
  CoreSessionOptions options = lockstep_demo();
  options.simulation.physics_threads = 2;
  Result<std::unique_ptr<CoreSession>> created = CoreSession::create(options);
  ASSERT_TRUE(created);
  CoreSession& session = **created;
  const LoopHelper* helper = session.simulation().physics_helper();
  ASSERT_NE(helper, nullptr);
  session.start();
  wait_for(session, [](const CoreStatus& s) { return s.next_tick > 200; });
  ASSERT_TRUE(session.send({CoreControlKind::kPause, {}, 0, 0, 1.0, {}}));
  wait_for(session, [](const CoreStatus& s) { return s.paused; });
  // The tick the pause arrived in may have called it in already: it goes home by itself.
  std::this_thread::sleep_for(2 * LoopHelper::kIdleOnCall + std::chrono::milliseconds(10));
  const std::uint64_t gone_home = helper->times_gone_home();
  for (int look = 0; look < 20; ++look) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(helper->on_call()) << "look " << look;
  }
  EXPECT_EQ(helper->times_gone_home(), gone_home) << "called in again while paused";
  session.stop();
}

TEST(CoreSession, LockstepRunIsTheHeadlessRunAndAStampedChangeAppliesAtItsTick) {
  Result<std::unique_ptr<CoreSession>> created = CoreSession::create(lockstep_demo());
  ASSERT_TRUE(created);
  CoreSession& session = **created;
  session.start();
  // Past the apex (demo: 1.1 s), where the sheath presses the tissue and stiffness matters.
  wait_for(session, [](const CoreStatus& s) { return s.next_tick > 1700; });
  ASSERT_TRUE(session.send({CoreControlKind::kPause, {}, 0, 0, 1.0, {}}));
  const CoreStatus paused = wait_for(session, [](const CoreStatus& s) { return s.paused; });
  const auto stamped = static_cast<std::int64_t>(session.next_tick());
  CoreControl change;
  change.kind = CoreControlKind::kParameter;
  change.id = 7;
  change.parameter = {stamped, TissueParameter::kStiffness, 200.0};
  ASSERT_TRUE(session.send(change));
  ASSERT_TRUE(session.send({CoreControlKind::kStep, {}, 0, 320, 1.0, {}}));
  const CoreStatus after = wait_for(session, [](const CoreStatus& s) { return s.applied_id[0] == 7 && s.pending_steps == 0; });
  session.stop();
  EXPECT_EQ(after.applied_tick[0], stamped) << "paused at the stamped tick, the change applies exactly there";
  EXPECT_EQ(after.parameters.get(TissueParameter::kStiffness), 200.0);
  EXPECT_EQ(paused.next_tick, static_cast<std::uint64_t>(stamped));

  const auto& live = session.collision_hashes();
  const std::vector<std::uint64_t> reference = headless_hashes(live.back().first + 1);
  ASSERT_GE(reference.size(), live.size());
  std::size_t before = 0, after_change = 0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    ASSERT_EQ(live[i].first, i * 16u);
    if (static_cast<std::int64_t>(live[i].first) < stamped) {
      EXPECT_EQ(live[i].second, reference[i]) << "collision step " << i << ", before the change";
      ++before;
    } else {
      EXPECT_NE(live[i].second, reference[i]) << "collision step " << i << ", after the change";
      ++after_change;
    }
  }
  EXPECT_GT(before, 10u);
  EXPECT_GT(after_change, 10u);
}

}  // namespace
}  // namespace resecto
