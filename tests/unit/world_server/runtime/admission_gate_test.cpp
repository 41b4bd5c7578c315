#include "marsala/world_server/runtime/admission_gate.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <random>

namespace marsala::world_server {
namespace {

using namespace std::chrono_literals;
using Clock = AdmissionGate::Clock;

// An arbitrary start: the gate must not depend on the clock's epoch.
const Clock::time_point t0 = Clock::time_point{} + 1000h;

TEST(AdmissionGate, ASessionIsConfirmedOnlyByAHelloRepeatedAtLeast100msAfterItsFirst) {
  AdmissionGate gate;
  const SenderKey agent{2, 0xabc};
  EXPECT_FALSE(gate.persistent(agent, t0));
  EXPECT_FALSE(gate.persistent(agent, t0 + 60ms));
  EXPECT_FALSE(gate.persistent(agent, t0 + 99ms));
  EXPECT_TRUE(gate.persistent(agent, t0 + 100ms));
  EXPECT_TRUE(gate.persistent(agent, t0 + 300ms));
  // Another session of the same id is a sender of its own.
  EXPECT_FALSE(gate.persistent({2, 0xabd}, t0 + 300ms));
}

// A copy of an agent's hello (its id and session, read on the default partition) written by another participant is
// another sender: the copy's repeats never confirm the agent's session, nor the agent's the copy's.
TEST(AdmissionGate, ACopyOfAHelloFromAnotherParticipantIsAnotherSender) {
  AdmissionGate gate;
  WriterPrefix agent_writer{}, copier{};
  agent_writer[11] = 1;
  copier[11] = 2;
  protocol::AgentHello hello;
  hello.agent_id = 3;
  hello.session = 0x77;
  EXPECT_FALSE(gate.persistent(sender_of(hello, agent_writer), t0));
  EXPECT_FALSE(gate.persistent(sender_of(hello, copier), t0 + 50ms));
  EXPECT_FALSE(gate.persistent(sender_of(hello, copier), t0 + 120ms));  // 70 ms after its own first: not yet
  EXPECT_TRUE(gate.persistent(sender_of(hello, agent_writer), t0 + 100ms));
  EXPECT_FALSE(sender_of(hello, agent_writer) == sender_of(hello, copier));
  EXPECT_TRUE(sender_of(hello, copier) < sender_of(hello, agent_writer) ||
              sender_of(hello, agent_writer) < sender_of(hello, copier));
}

TEST(AdmissionGate, AHelloIsRememberedAcrossOneGenerationNotTwo) {
  AdmissionGate gate;
  const SenderKey agent{1, 7};
  EXPECT_FALSE(gate.persistent(agent, t0));
  // The next generation starts at t0 + 1 s; the first hello is still known there.
  EXPECT_TRUE(gate.persistent(agent, t0 + 1500ms));
  AdmissionGate other;
  EXPECT_FALSE(other.persistent(agent, t0));
  EXPECT_FALSE(other.persistent({9, 9}, t0 + 1000ms));   // rotates: agent's hello is now in the previous generation
  EXPECT_FALSE(other.persistent({9, 10}, t0 + 2000ms));  // rotates again: it is forgotten
  EXPECT_FALSE(other.persistent(agent, t0 + 2000ms));    // so this is a first hello again
}

TEST(AdmissionGate, AFloodOfOneShotRandomSessionsIsNeverConfirmedAndStaysBounded) {
  AdmissionGate gate;
  std::mt19937_64 random(23);
  std::size_t confirmed = 0, most_remembered = 0;
  // 64 new random senders per 20 ms round for 10 s (32,000 senders), each saying hello once.
  for (int round = 0; round < 500; ++round) {
    const Clock::time_point now = t0 + round * 20ms;
    for (int k = 0; k < 64; ++k) {
      const SenderKey sender{static_cast<std::uint32_t>(random() % 200), random()};
      confirmed += gate.persistent(sender, now) ? 1 : 0;
    }
    most_remembered = std::max(most_remembered, gate.remembered());
  }
  EXPECT_EQ(confirmed, 0u);
  // Two generations of 1 s at 3,200 hellos per second at most.
  EXPECT_LE(most_remembered, 2u * 3200u + 64u);
}

TEST(AdmissionGate, ATakeoverWaitsThreeSecondsWhileTheOldSessionIsConnected) {
  AdmissionGate gate;
  const SenderKey restarted{3, 0x2};
  EXPECT_EQ(gate.takeover(restarted, true, t0), TakeoverWait::kWaiting);  // said hello once: no notice yet
  EXPECT_EQ(gate.takeover(restarted, true, t0 + 200ms), TakeoverWait::kStarted);
  EXPECT_EQ(gate.takeover(restarted, true, t0 + 400ms), TakeoverWait::kWaiting);
  EXPECT_EQ(gate.takeover(restarted, true, t0 + 3199ms), TakeoverWait::kWaiting);
  EXPECT_EQ(gate.takeover(restarted, true, t0 + 3200ms), TakeoverWait::kNone);  // 3 s after the wait began
  // A slot not held by a connected session never waits.
  EXPECT_EQ(AdmissionGate().takeover(restarted, false, t0), TakeoverWait::kNone);
}

TEST(AdmissionGate, AnswersEachSenderAtMostEvery150ms) {
  AdmissionGate gate;
  const SenderKey agent{1, 1};
  EXPECT_TRUE(gate.may_answer(agent, t0));
  EXPECT_FALSE(gate.may_answer(agent, t0 + 100ms));
  EXPECT_FALSE(gate.may_answer(agent, t0 + 149ms));
  EXPECT_TRUE(gate.may_answer(agent, t0 + 150ms));
  EXPECT_TRUE(gate.may_answer({1, 2}, t0 + 150ms));  // each sender has its own rate
}

TEST(AdmissionGate, TheAnswerAndRefusalMemoriesStayBounded) {
  AdmissionGate gate;
  for (std::uint64_t s = 0; s < 20000; ++s) {
    EXPECT_TRUE(gate.may_answer({1, s}, t0));
    gate.report_refusal({1, s});
    gate.takeover({1, s}, true, t0 + std::chrono::milliseconds(s % 2 == 0 ? 0 : 200));
  }
  EXPECT_LE(gate.remembered(), 4096u + 1024u + 1024u + 2u * 20000u);
  AdmissionGate answers;
  for (std::uint64_t s = 0; s < 20000; ++s) answers.may_answer({1, s}, t0);
  EXPECT_LE(answers.remembered(), 4096u);
}

TEST(AdmissionGate, ReportsARefusalOncePerSenderThenEveryPowerOfTen) {
  AdmissionGate gate;
  EXPECT_TRUE(gate.report_refusal({5, 1}));
  EXPECT_FALSE(gate.report_refusal({5, 1}));
  EXPECT_TRUE(gate.report_refusal({5, 2}));
  EXPECT_EQ(gate.refusals(), 3u);
  // Fill the memory of refused senders (1,024), then only the 10,000th refusal is reported among the next ones.
  std::uint64_t s = 3;
  while (gate.refusals() < 1024 + 1) gate.report_refusal({6, s++});
  int reported = 0;
  while (gate.refusals() < 20000) reported += gate.report_refusal({7, s++}) ? 1 : 0;
  EXPECT_EQ(reported, 1);  // the 10,000th
}

TEST(AdmissionGate, AnswersAtMostSixteenRefusalsPerRound) {
  AdmissionGate gate;
  gate.begin_round();
  int answered = 0;
  for (int k = 0; k < 100; ++k) answered += gate.may_answer_refusal() ? 1 : 0;
  EXPECT_EQ(answered, 16);
  gate.begin_round();
  EXPECT_TRUE(gate.may_answer_refusal());
}

}  // namespace
}  // namespace marsala::world_server
