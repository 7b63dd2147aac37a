// End-to-end behaviour of the command-line front end that every command shares.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_support.hpp"

using rwcalc::test::run_cli;
using rwcalc::test::run_exe;

TEST(Cli, VersionPrintsTheProjectVersionAndCommit) {
  auto r = run_exe({"--version"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find(std::string("rwcalc ") + RWCALC_VERSION + " (commit "), std::string::npos) << r.out;
}

// The manual page and the completion come from the parser's own definitions: every command, and
// every option of a command's --help, appears in both.
TEST(Cli, ManualPageAndCompletionDescribeEveryCommandAndOption) {
  const auto man = run_cli({"man"});
  const auto completion = run_cli({"completion"});
  ASSERT_EQ(man.status, 0) << man.err;
  ASSERT_EQ(completion.status, 0) << completion.err;
  EXPECT_TRUE(man.out.starts_with(".TH RWCALC 1 ")) << man.out.substr(0, 80);
  for (const char* cmd : {"allan", "analyze", "batch", "simulate", "diagnose", "report", "merge"}) {
    EXPECT_NE(man.out.find(std::string(".SS \"rwcalc ") + cmd + " "), std::string::npos) << cmd;
    EXPECT_NE(completion.out.find(std::string(cmd) + ") opts=\""), std::string::npos) << cmd;
    const auto help = run_cli({cmd, "--help"});
    for (std::size_t at = help.out.find("  --"); at != std::string::npos; at = help.out.find("  --", at + 1)) {
      const std::string option = help.out.substr(at + 2, help.out.find_first_of(" ,=\n", at + 2) - at - 2);
      std::string in_roff;  // minus signs are escaped in roff
      for (char c : option) in_roff += c == '-' ? std::string("\\-") : std::string(1, c);
      EXPECT_NE(man.out.find(in_roff), std::string::npos) << cmd << " " << option;
      EXPECT_NE(completion.out.find(" " + option), std::string::npos) << cmd << " " << option;
    }
  }
  EXPECT_NE(completion.out.find("complete -o filenames -F _rwcalc rwcalc"), std::string::npos);
}

// The completion run by bash: each candidate is a whole file name, never split at a blank nor
// expanded as a pattern.
TEST(Cli, CompletionOffersFileNamesWithBlanksAndPatternCharactersWhole) {
  if (std::system("command -v bash >/dev/null 2>&1") != 0) GTEST_SKIP() << "no bash";
  const rwcalc::test::TempDir dir;
  const auto script = dir.write("rwcalc.bash", run_cli({"completion"}).out);
  const auto files = dir.path() / "files";
  std::filesystem::create_directory(files);
  for (const char* name : {"run 1.csv", "run*2.csv", "run$3 [x].csv", "other.csv"})
    (void)dir.write(std::string("files/") + name, "1\n");
  const auto out = dir.path() / "candidates";
  const std::string cmd = "cd '" + files.string() + "' && bash -c '. \"$0\"; COMP_WORDS=(rwcalc analyze run); " +
                          "COMP_CWORD=2; _rwcalc; printf \"%s\\n\" \"${COMPREPLY[@]}\"' '" + script.string() +
                          "' | LC_ALL=C sort > '" + out.string() + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_EQ(rwcalc::test::slurp(out), "run 1.csv\nrun$3 [x].csv\nrun*2.csv\n");
  // Options complete as before.
  const std::string opts = "bash -c '. \"$0\"; COMP_WORDS=(rwcalc imu --kal); COMP_CWORD=2; _rwcalc; " +
                           std::string("printf \"%s\\n\" \"${COMPREPLY[@]}\"' '") + script.string() + "' > '" +
                           out.string() + "'";
  ASSERT_EQ(std::system(opts.c_str()), 0) << opts;
  EXPECT_EQ(rwcalc::test::slurp(out), "--kalibr\n");
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
  auto r = run_cli({"analyz", "x.csv"});  // ("analyse" is analyze spelt the British way)
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
