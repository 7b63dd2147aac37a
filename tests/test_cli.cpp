// End-to-end behaviour of the command-line front end that every command shares.
#include <gtest/gtest.h>

#include "test_support.hpp"

using rwcalc::test::run_cli;
using rwcalc::test::run_exe;

TEST(Cli, VersionPrintsTheProjectVersion) {
  auto r = run_exe({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find(std::string("rwcalc ") + RWCALC_VERSION), std::string::npos) << r.out;
}

TEST(Cli, HelpListsEveryCommand) {
  auto r = run_cli({"--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* cmd : {"allan", "analyze", "batch", "simulate", "diagnose", "report", "merge"})
    EXPECT_NE(r.out.find(cmd), std::string::npos) << cmd << "\n" << r.out;
}

TEST(Cli, EachCommandsHelpAndAnUnknownCommand) {
  // A command named first is set up alone; its help is its own, and a name that is no command
  // still gets the list of them all.
  for (const char* cmd : {"allan", "analyze", "batch", "simulate", "diagnose", "report", "merge"}) {
    auto r = run_cli({cmd, "--help"});
    EXPECT_EQ(r.status, 0) << cmd;
    EXPECT_NE(r.out.find(std::string("rwcalc ") + cmd), std::string::npos) << cmd << "\n" << r.out;
  }
  auto r = run_cli({"analyse", "x.csv"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("rwcalc --help"), std::string::npos) << r.err;
  // An option before the command: every command is set up, and the option is honoured.
  auto v = run_cli({"--version", "analyze"});
  EXPECT_EQ(v.status, 0);
  EXPECT_NE(v.out.find(RWCALC_VERSION), std::string::npos) << v.out;
}

TEST(Cli, NoCommandIsAUsageErrorWithStatusTwo) {
  auto r = run_exe({});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--help"), std::string::npos) << r.err;
}

TEST(Cli, UnknownOptionIsAUsageErrorWithStatusTwo) {
  auto r = run_cli({"allan", "--no-such-option", "x.csv"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no-such-option"), std::string::npos) << r.err;
}
