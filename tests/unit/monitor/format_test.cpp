// The monitor's lines, checked against hand-written golden strings.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "marsala/monitor/format.hpp"

namespace marsala::monitor {
namespace {

protocol::AgentStatus agent(std::uint32_t id, const std::string& state, double material_m3 = 1.0, bool alive = true,
                            bool at_goal = false) {
  protocol::AgentStatus a;
  a.agent_id = id;
  a.name = "builder-" + std::to_string(id);
  a.state = state;
  a.material_m3 = material_m3;
  a.alive = alive;
  a.at_goal = at_goal;
  return a;
}

protocol::WorldStatus three_agents() {
  protocol::WorldStatus s;
  s.run_id = "r7";
  s.scenario = "ramp";
  s.step = 42;
  s.deposited_volume_m3 = 0.125;
  s.progress = 1.0 / 3.0;
  // Out of id order on purpose: the columns follow the ids.
  s.agents = {agent(2, "refill", 2.25, true, true), agent(1, "build", 1.5), agent(3, "follow", 0.5, false)};
  return s;
}

TEST(Format, StepHeaderAndLineWithFewAgents) {
  const protocol::WorldStatus s = three_agents();
  EXPECT_EQ(format_step_header(s), "  step  live mat[m3]  dep[m3] prog | 1           2           3");
  // mat counts the live agents only (1.5 + 2.25); agent 2 at its goal, agent 3 dropped.
  EXPECT_EQ(format_step_line(s), "    42   2/3    3.75    0.125  33% | build       refill*     --");
  // A team of four whose slot 4 was never admitted: live counts against the team.
  protocol::WorldStatus four = s;
  four.team_size = 4;
  EXPECT_EQ(format_step_line(four), "    42   2/4    3.75    0.125  33% | build       refill*     --");
}

TEST(Format, TwelveAgentsFitOneHundredColumns) {
  protocol::WorldStatus s;
  s.step = 7;
  s.progress = 1.0 / 12.0;
  for (std::uint32_t id = 1; id <= 12; ++id) s.agents.push_back(agent(id, "build"));
  s.agents[2] = agent(3, "climb", 1.0, true, true);
  s.agents[4] = agent(5, "build", 1.0, false);
  s.agents[6] = agent(7, "");
  s.agents[11] = agent(12, "navigate_to_site");
  EXPECT_EQ(agent_column_text_width(12), 4);
  EXPECT_EQ(format_step_header(s),
            "  step  live mat[m3]  dep[m3] prog | 1    2    3    4    5    6    7    8    9    10   11   12");
  const std::string line = format_step_line(s);
  EXPECT_EQ(line, "     7 11/12   11.00    0.000   8% | buil buil cli* buil --   buil ?    buil buil buil buil navi");
  EXPECT_LE(line.size(), 100u);
}

TEST(Format, BeyondTwelveAgentsCountsLiveAgentsPerState) {
  protocol::WorldStatus s;
  s.step = 3;
  s.deposited_volume_m3 = 2.5;
  for (std::uint32_t id = 1; id <= 13; ++id) {
    const std::string state = id <= 6 ? "build" : id <= 10 ? "refill" : id <= 12 ? "follow" : "climb";
    s.agents.push_back(agent(id, state, 0.25, id != 12));
  }
  EXPECT_EQ(agent_column_text_width(13), 0);
  EXPECT_EQ(format_step_header(s), "  step  live mat[m3]  dep[m3] prog | live agents by state");
  // Most frequent first, ties by name; the dropped "follow" is not counted.
  EXPECT_EQ(format_step_line(s), "     3 12/13    3.00    2.500   0% | build 6, refill 4, climb 1, follow 1");

  // Without a width limit every agent keeps its column.
  EXPECT_EQ(agent_column_text_width(13, FormatOptions{0}), kMaxAgentColumnText);
  EXPECT_NE(format_step_line(s, FormatOptions{0}).find("| build       build"), std::string::npos);
}

TEST(Format, LongLinesEndInEllipsisAtTheWidth) {
  protocol::WorldStatus s;
  for (std::uint32_t id = 1; id <= 40; ++id) s.agents.push_back(agent(id, "state_number_" + std::to_string(id)));
  const std::string line = format_step_line(s);
  EXPECT_EQ(line.size(), 100u);
  EXPECT_EQ(line.substr(97), "...");
  EXPECT_EQ(line.substr(0, 60), "     0 40/40   40.00    0.000   0% | state_number_1 1, state");
  EXPECT_EQ(fit_width("abcdef", 6), "abcdef");
  EXPECT_EQ(fit_width("abcdefg", 6), "abc...");
  EXPECT_EQ(fit_width("abcdefg", 0), "abcdefg");
  EXPECT_EQ(fit_width("abcdefg", 2), "ab");
}

TEST(Format, NoAgents) {
  protocol::WorldStatus s;
  EXPECT_EQ(format_step_header(s), "  step  live mat[m3]  dep[m3] prog | no agents");
  EXPECT_EQ(format_step_line(s), "     0   0/0    0.00    0.000   0% | no agents");
}

TEST(Format, EventLines) {
  protocol::WorldEvent e;
  e.step = 42;
  e.agent_id = 3;
  e.kind = protocol::EventKind::kDeposited;
  e.volume_m3 = 0.000125;
  e.detail = "5 cells";
  EXPECT_EQ(format_event(e), "    42 > agent 3  deposited 0.000125 m3 5 cells");

  e = {};
  e.step = 7;
  e.agent_id = 12;
  e.kind = protocol::EventKind::kRejected;
  e.detail = "target 0.31 m away > max_step 0.2 m";
  EXPECT_EQ(format_event(e), "     7 > agent 12 rejected  target 0.31 m away > max_step 0.2 m");

  e = {};
  e.step = 100;
  e.kind = protocol::EventKind::kRunOver;
  e.detail = "completed";
  EXPECT_EQ(format_event(e), "   100 > world    run_over  completed");

  e = {};
  e.agent_id = 1;
  e.kind = protocol::EventKind::kAdmitted;
  EXPECT_EQ(format_event(e), "     0 > agent 1  admitted");

  e = {};
  e.step = 1;
  e.agent_id = 2;
  e.kind = static_cast<protocol::EventKind>(42);  // a kind this monitor does not know yet
  e.detail = "x";
  EXPECT_EQ(format_event(e), "     1 > agent 2  kind 42   x");
}

TEST(Format, EventKindsByNameOrNumber) {
  EXPECT_EQ(event_kind(protocol::EventKind::kDeposited), "deposited");
  EXPECT_EQ(event_kind(protocol::EventKind::kRunOver), "run_over");
  EXPECT_EQ(event_kind(static_cast<protocol::EventKind>(200)), "kind 200");
}

TEST(Format, TextFromTheWireCannotDriveTheTerminal) {
  protocol::WorldEvent e;
  e.step = 5;
  e.agent_id = 4;
  e.kind = protocol::EventKind::kRefused;
  e.detail = "bad\x1b[2Jname\n\xc3\xa9";
  EXPECT_EQ(format_event(e), "     5 > agent 4  refused   bad?[2Jname???");

  protocol::WorldStatus s;
  s.agents = {agent(1, "evil\r\tstate")};
  EXPECT_EQ(format_step_line(s), "     0   1/1    1.00    0.000   0% | evil??state");
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a?b");
}

TEST(Format, LongEventDetailIsCut) {
  protocol::WorldEvent e;
  e.step = 9;
  e.agent_id = 1;
  e.kind = protocol::EventKind::kRejected;
  e.detail = std::string(200, 'r');
  const std::string line = format_event(e);
  EXPECT_EQ(line, "     9 > agent 1  rejected  " + std::string(69, 'r') + "...");
  EXPECT_EQ(format_event(e, FormatOptions{0}).size(), 28u + 200u);
}

TEST(Format, RunSummary) {
  protocol::WorldStatus s = three_agents();
  s.step = 1234;
  s.wall_seconds = 12.34;
  s.deposited_volume_m3 = 1.25;
  s.running = false;
  s.completed = true;
  s.agents[0].accepted = 100;
  s.agents[1].accepted = 120;
  s.agents[1].rejected = 2;
  s.agents[2].accepted = 140;
  s.agents[2].missed = 3;
  // Agent 3 was dropped: the line says the run was short of it.
  EXPECT_EQ(format_run_summary(s),
            "run r7 completed at step 1234 (12.3 s) | live 2/3, at goal 1 | missing 1 of 3 slots: 3 dropped | "
            "dep 1.250 m3 | acc 360 rej 2 miss 3");
  s.completed = false;
  EXPECT_EQ(format_run_summary(s),
            "run r7 stopped at step 1234 (12.3 s) | live 2/3, at goal 1 | missing 1 of 3 slots: 3 dropped | "
            "dep 1.250 m3 | acc 360 rej 2 miss 3");
}

TEST(Format, RunSummaryNamesTheSlotsNeverAdmitted) {
  protocol::WorldStatus s = three_agents();
  s.running = false;
  s.completed = true;
  s.agents[2].alive = true;  // the three listed are all in the run
  EXPECT_EQ(format_run_summary(s),
            "run r7 completed at step 42 (0.0 s) | live 3/3, at goal 1 | dep 0.125 m3 | acc 0 rej 0 miss 0");
  // A team of five: slots 4 and 5 never admitted (the world lists admitted agents only).
  s.team_size = 5;
  s.agents[0].alive = false;
  EXPECT_EQ(format_run_summary(s),
            "run r7 completed at step 42 (0.0 s) | live 2/5, at goal 0 | missing 3 of 5 slots: 2 dropped, "
            "4 never admitted, 5 never admitted | dep 0.125 m3 | acc 0 rej 0 miss 0");
}

TEST(Format, StatusTable) {
  protocol::WorldStatus s;
  s.run_id = "r7";
  s.scenario = "ramp";
  s.step = 42;
  s.wall_seconds = 3.5;
  s.progress = 0.5;
  s.deposited_volume_m3 = 0.625;
  protocol::AgentStatus a = agent(1, "build", 1.25);
  a.x_m = 2.5;
  a.y_m = 3.75;
  a.z_m = 0.25;
  a.deposited_m3 = 0.125;
  a.accepted = 40;
  a.rejected = 1;
  protocol::AgentStatus b = agent(2, "navigate_to_site", 0.0, false);
  b.name = "a-very-long-name-x";
  b.x_m = -10.5;
  b.z_m = 1.5;
  b.deposited_m3 = 0.5;
  b.accepted = 3;
  b.missed = 2;
  s.agents = {b, a};
  const std::vector<std::string> expected = {
      "run r7  scenario ramp  step 42  wall 3.5 s  running  progress 50.0%  deposited 0.6250 m3",
      " id name         state           x[m]     y[m]    z[m] mat[m3] dep[m3]   acc  rej miss alive goal",
      "  1 builder-1    build           2.50     3.75   0.250  1.2500  0.1250    40    1    0 yes   no",
      "  2 a-very-long- navigate_to   -10.50     0.00   1.500  0.0000  0.5000     3    0    2 no    no",
      "    total        2 agents                               1.2500  0.6250    43    1    2 1     0",
  };
  EXPECT_EQ(format_status_table(s), expected);
  for (const std::string& line : format_status_table(s)) EXPECT_LE(line.size(), 100u) << line;

  s.running = false;
  s.completed = true;
  EXPECT_EQ(format_status_table(s)[0],
            "run r7  scenario ramp  step 42  wall 3.5 s  completed  progress 50.0%  deposited 0.6250 m3");
}

}  // namespace
}  // namespace marsala::monitor
