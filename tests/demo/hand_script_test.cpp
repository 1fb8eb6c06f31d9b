// The scripted hand of autograv-demo: parsing, error messages with file and line, playback.
#include "hand_script.h"

#include <gtest/gtest.h>

#include <string>

#include "autograv/error.h"

namespace autograv::demo {
namespace {

std::string parseError(const std::string& text) {
  try {
    HandScript::parse(text, "s.txt");
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

TEST(HandScriptTest, ParsesEveryActionInTimeOrder) {
  const HandScript script = HandScript::parse(
      "# lift and drop\n"
      "\n"
      "at 1.5 release   # let go\n"
      "at 0.1 grab\n"
      "at 0.2 move 0.01 -0.02 0.03\n"
      "at 0.2 move 0 0 0.05 0.04\n"
      "at 2 compensation off\n"
      "at 3 compensation on\n",
      "s.txt");
  const auto& events = script.events();
  ASSERT_EQ(events.size(), 6u);
  EXPECT_EQ(events[0].kind, HandEvent::Kind::kGrab);
  EXPECT_DOUBLE_EQ(events[0].time_s, 0.1);
  EXPECT_EQ(events[0].line, 4);
  EXPECT_EQ(events[1].kind, HandEvent::Kind::kMove);
  EXPECT_TRUE(events[1].position_m.isApprox(Eigen::Vector3d(0.01, -0.02, 0.03)));
  EXPECT_DOUBLE_EQ(events[1].speed_m_per_s, 0.1);  // the default glide speed
  EXPECT_EQ(events[2].line, 6);                    // same time: file order kept
  EXPECT_DOUBLE_EQ(events[2].speed_m_per_s, 0.04);
  EXPECT_EQ(events[3].kind, HandEvent::Kind::kRelease);
  EXPECT_DOUBLE_EQ(events[3].time_s, 1.5);
  EXPECT_EQ(events[4].kind, HandEvent::Kind::kCompensationOff);
  EXPECT_EQ(events[5].kind, HandEvent::Kind::kCompensationOn);
}

TEST(HandScriptTest, ErrorsNameTheLineAndWhatWasExpected) {
  EXPECT_NE(parseError("at 0 grab\nwhen 1 grab\n").find("s.txt:2: expected 'at T grab'"),
            std::string::npos);
  EXPECT_NE(parseError("at soon grab\n").find("s.txt:1: expected a time in seconds"),
            std::string::npos);
  EXPECT_NE(parseError("at -1 grab\n").find("s.txt:1: times must not be negative"),
            std::string::npos);
  EXPECT_NE(parseError("\n\nat 1 move 0 0\n").find("s.txt:3: expected z in metres"),
            std::string::npos);
  EXPECT_NE(parseError("at 1 move 0 0 0 -2\n").find("speed must be positive"), std::string::npos);
  EXPECT_NE(parseError("at 1 grab now\n").find("unexpected 'now'"), std::string::npos);
  EXPECT_NE(parseError("at 1 compensation maybe\n").find("'compensation on'"), std::string::npos);
  EXPECT_NE(parseError("at 1 jump\n").find("s.txt:1"), std::string::npos);
  EXPECT_NE(parseError("at 1e400 grab\n").find("expected a time"), std::string::npos);
}

TEST(HandScriptTest, MissingFileIsReportedByName) {
  try {
    HandScript::load("/nonexistent/hand.txt");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/hand.txt"), std::string::npos);
  }
}

TEST(HandScriptPlayerTest, HandsOutEachEventOnceWhenDue) {
  const HandScript script =
      HandScript::parse("at 0.1 grab\nat 0.1 move 0 0 0.01\nat 0.5 release\n", "s");
  HandScriptPlayer player(&script);
  EXPECT_EQ(player.nextDue(0.05), nullptr);
  const HandEvent* first = player.nextDue(0.1);
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->kind, HandEvent::Kind::kGrab);
  const HandEvent* second = player.nextDue(0.1);
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(second->kind, HandEvent::Kind::kMove);
  EXPECT_EQ(player.nextDue(0.2), nullptr);
  EXPECT_FALSE(player.finished());
  const HandEvent* third = player.nextDue(10.0);
  ASSERT_NE(third, nullptr);
  EXPECT_EQ(third->kind, HandEvent::Kind::kRelease);
  EXPECT_EQ(player.nextDue(10.0), nullptr);
  EXPECT_TRUE(player.finished());
  HandScriptPlayer none;
  EXPECT_EQ(none.nextDue(1.0), nullptr);
  EXPECT_TRUE(none.finished());
}

}  // namespace
}  // namespace autograv::demo
