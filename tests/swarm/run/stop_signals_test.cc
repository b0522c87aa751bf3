// SIGINT, SIGTERM and SIGHUP as requests to stop (swarm/run/stop_signals.cc):
// the first is noted, not acted on, and so is a second soon after it; a
// later one acts as usual; the handlers
// before are restored; a signal pending while blocked is noted on creation.
#include "swarm/run/stop_signals.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

namespace swarmsim {
namespace {

// These tests raise SIGHUP: under nohup (a CI's wrapper) it starts ignored,
// which StopSignals keeps (tested below).
const bool g_hang_up_as_usual = std::signal(SIGHUP, SIG_DFL) != SIG_ERR;

TEST(StopSignalsTest, TheFirstSignalIsNotedAndTheProgramGoesOn) {
  ASSERT_TRUE(g_hang_up_as_usual);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    StopSignals stop;
    EXPECT_EQ(StopSignals::Received(), 0);
    ASSERT_EQ(raise(sig), 0);
    EXPECT_EQ(StopSignals::Received(), sig);  // and this process still runs
  }
}

TEST(StopSignalsTest, ANewOneForgetsAnOldSignalANestedOneKeepsIt) {
  {
    StopSignals outer;
    ASSERT_EQ(raise(SIGHUP), 0);
    StopSignals inner;  // the run's, inside the program's for the load
    EXPECT_EQ(StopSignals::Received(), SIGHUP);
  }
  StopSignals next;
  EXPECT_EQ(StopSignals::Received(), 0);
}

TEST(StopSignalsTest, ASecondSignalSoonAfterIsTheSameRequest) {
  // Ctrl-C pressed twice: the run still writes its outputs (a second one
  // 10 ms after the first killed it with summary.json saying running).
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        StopSignals stop;
        raise(SIGINT);
        raise(SIGTERM);
        raise(SIGINT);
        _exit(StopSignals::Received() == SIGINT ? 7 : 8);
      },
      ::testing::ExitedWithCode(7), "");
}

TEST(StopSignalsTest, ASecondSignalAfterTheGraceActsAsUsual) {
  // A stuck program can still be stopped: a later Ctrl-C ends it.
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        StopSignals::SetGraceMs(0);
        StopSignals stop;
        raise(SIGINT);
        raise(SIGINT);
        _exit(0);
      },
      ::testing::KilledBySignal(SIGINT), "");
}

volatile sig_atomic_t g_own_handler_calls = 0;
extern "C" void OwnHandler(int) { g_own_handler_calls = g_own_handler_calls + 1; }

TEST(StopSignalsTest, TheHandlersBeforeAreRestored) {
  struct sigaction own {
  }, before{};
  own.sa_handler = OwnHandler;
  sigemptyset(&own.sa_mask);
  ASSERT_EQ(sigaction(SIGTERM, &own, &before), 0);
  {
    StopSignals stop;
    raise(SIGTERM);
    EXPECT_EQ(g_own_handler_calls, 0);
    EXPECT_EQ(StopSignals::Received(), SIGTERM);
  }
  raise(SIGTERM);
  EXPECT_EQ(g_own_handler_calls, 1);
  sigaction(SIGTERM, &before, nullptr);
}

TEST(StopSignalsTest, ASignalPendingWhileBlockedIsNotedOnCreation) {
  // A batch system's wrapper may start the program with them blocked.
  sigset_t mask, old;
  sigemptyset(&mask);
  sigaddset(&mask, SIGTERM);
  ASSERT_EQ(pthread_sigmask(SIG_BLOCK, &mask, &old), 0);
  struct sigaction default_action {
  }, before{};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(SIGTERM, &default_action, &before);
  ASSERT_EQ(raise(SIGTERM), 0);  // pending: blocked
  {
    StopSignals stop;  // unblocks: the signal arrives, and is only noted
    EXPECT_EQ(StopSignals::Received(), SIGTERM);
  }
  // Had it stayed pending, ignoring it discards it (instead of ending the tests).
  signal(SIGTERM, SIG_IGN);
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  sigaction(SIGTERM, &before, nullptr);
}

TEST(StopSignalsTest, AHangUpIgnoredAtTheStartStaysIgnored) {
  // nohup: closing the terminal does not stop the run.
  ASSERT_NE(std::signal(SIGHUP, SIG_IGN), SIG_ERR);
  {
    StopSignals stop;
    ASSERT_EQ(raise(SIGHUP), 0);
    EXPECT_EQ(StopSignals::Received(), 0);
    ASSERT_EQ(raise(SIGTERM), 0);  // the others are still requests to stop
    EXPECT_EQ(StopSignals::Received(), SIGTERM);
  }
  struct sigaction now {};
  ASSERT_EQ(sigaction(SIGHUP, nullptr, &now), 0);
  EXPECT_EQ(now.sa_handler, SIG_IGN);
  std::signal(SIGHUP, SIG_DFL);
}

}  // namespace
}  // namespace swarmsim
