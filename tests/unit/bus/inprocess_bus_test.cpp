#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "marsala/bus/bus.hpp"
#include "marsala/core/error.hpp"

namespace marsala::bus {
using namespace marsala::protocol;  // the messages under test
namespace {

using namespace std::chrono_literals;

TEST(InProcessBus, DeliversInOrderWithinAPartitionOnly) {
  auto participant = make_participant({Vendor::kInProcess, 11});
  auto signal = std::make_shared<Signal>();
  auto mine = participant->create_reader<SensorFrame>({"run/agent-1", signal});
  auto other = participant->create_reader<SensorFrame>({"run/agent-2", nullptr});
  auto writer = participant->create_writer<SensorFrame>({"run/agent-1", nullptr});
  EXPECT_EQ(writer->matched_readers(), 1);
  for (std::uint64_t step = 0; step < 5; ++step) {
    SensorFrame f;
    f.agent_id = 1;
    f.step = step;
    writer->write(f);
  }
  EXPECT_TRUE(signal->wait_for(0ms));
  const auto frames = mine->take();
  ASSERT_EQ(frames.size(), 5u);
  for (std::uint64_t step = 0; step < 5; ++step) EXPECT_EQ(frames[step].step, step);
  EXPECT_TRUE(other->take().empty());
  EXPECT_TRUE(mine->take().empty());
}

TEST(InProcessBus, DomainsAreSeparate) {
  auto a = make_participant({Vendor::kInProcess, 12});
  auto b = make_participant({Vendor::kInProcess, 13});
  auto reader = b->create_reader<AgentHello>();
  a->create_writer<AgentHello>()->write(AgentHello{});
  EXPECT_TRUE(reader->take().empty());
}

TEST(InProcessBus, TransientLocalReplaysTheLatestToLateReaders) {
  auto participant = make_participant({Vendor::kInProcess, 14});
  auto writer = participant->create_writer<WorldStatus>({"", nullptr, Durability::kTransientLocal, 1});
  WorldStatus s;
  s.step = 41;
  writer->write(s);
  s.step = 42;
  writer->write(s);
  auto late = participant->create_reader<WorldStatus>({"", nullptr, Durability::kTransientLocal, 1});
  const auto got = late->take();
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].step, 42u);
  auto volatile_reader = participant->create_reader<WorldStatus>();
  EXPECT_TRUE(volatile_reader->take().empty());
}

TEST(InProcessBus, WriterLivelinessAndWakeUps) {
  auto participant = make_participant({Vendor::kInProcess, 15});
  auto signal = std::make_shared<Signal>();
  auto reader = participant->create_reader<ActionRequest>({"run/agent-3", signal});
  EXPECT_EQ(reader->alive_writers(), 0);
  signal->wait_for(0ms);
  auto writer = participant->create_writer<ActionRequest>({"run/agent-3", nullptr});
  EXPECT_EQ(reader->alive_writers(), 1);
  EXPECT_TRUE(signal->wait_for(0ms));  // a writer came
  std::thread killer([&] {
    std::this_thread::sleep_for(20ms);
    writer.reset();
  });
  EXPECT_TRUE(signal->wait_for(5s));  // woken when the writer goes
  killer.join();
  EXPECT_EQ(reader->alive_writers(), 0);
}

// A reader with an on_data handler: the handler runs when a sample comes (on the writing thread here, on the DDS
// backend's own thread there) and can take it at once; the Signal is then left for writers coming and going.
TEST(InProcessBus, AnOnDataHandlerTakesSamplesInPlaceOfTheSignal) {
  auto participant = make_participant({Vendor::kInProcess, 16});
  auto signal = std::make_shared<Signal>();
  std::vector<std::uint64_t> taken;
  std::vector<std::thread::id> threads;
  std::unique_ptr<Reader<SensorFrame>> reader;
  reader = participant->create_reader<SensorFrame>({"run/agent-4", signal, Durability::kVolatile, 64, [&] {
                                                      threads.push_back(std::this_thread::get_id());
                                                      for (const SensorFrame& f : reader->take()) taken.push_back(f.step);
                                                    }});
  auto writer = participant->create_writer<SensorFrame>({"run/agent-4", nullptr});
  EXPECT_TRUE(signal->wait_for(0ms));  // a writer came: still signalled
  for (std::uint64_t step = 0; step < 3; ++step) {
    SensorFrame f;
    f.step = step;
    writer->write(f);
    ASSERT_EQ(taken.size(), step + 1) << "taken before write() returned";
  }
  EXPECT_EQ(taken, (std::vector<std::uint64_t>{0, 1, 2}));
  EXPECT_EQ(threads, std::vector<std::thread::id>(3, std::this_thread::get_id()));
  EXPECT_FALSE(signal->wait_for(0ms));  // data alone does not signal
}

TEST(Bus, NamesAndErrors) {
  EXPECT_EQ(vendor_from_string("cyclone"), Vendor::kCyclone);
  EXPECT_EQ(vendor_from_string("fastdds"), Vendor::kFastDds);
  EXPECT_THROW(vendor_from_string("opensplice"), InvalidArgument);
  EXPECT_THROW(make_participant({Vendor::kInProcess, 233}), InvalidArgument);
  EXPECT_EQ(partition_for("r7", 12, 0xab), "r7/agent-12-00000000000000ab");
  for (EventKind k : {EventKind::kAdmitted, EventKind::kDropped, EventKind::kRunOver})
    EXPECT_EQ(event_kind_from_string(to_string(k)), k);
  EXPECT_THROW(event_kind_from_string("exploded"), InvalidArgument);
}

}  // namespace
}  // namespace marsala::bus
