// nsgraph: one binary, one subcommand per pipeline stage (docs/architecture.md).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "commands.h"
#include "nsg/core/error.h"
#include "nsg/core/log.h"
#include "nsg/core/options.h"
#include "nsg/core/version.h"

namespace {

// The one explicit command table (no self-registering statics).
constexpr nsg::cli::AddCommand kCommands[] = {
    &nsg::cli::add_synth_command,    &nsg::cli::add_inspect_command,      &nsg::cli::add_segment_command,
    &nsg::cli::add_generate_command, &nsg::cli::add_merge_command,        &nsg::cli::add_stats_command,
    &nsg::cli::add_score_command,    &nsg::cli::add_preview_command,      &nsg::cli::add_report_command,
    &nsg::cli::add_validate_command, &nsg::cli::add_export_cloud_command, &nsg::cli::add_train_command,
    &nsg::cli::add_predict_command,  &nsg::cli::add_frames_command,       &nsg::cli::add_graphify_command,
};

// The command names of `app`, in table order.
std::vector<std::string> command_names(CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

// The subcommand of `parent` called `word`, or nullptr.
CLI::App* subcommand_named(CLI::App& parent, const std::string& word) {
  for (CLI::App* sub : parent.get_subcommands([](CLI::App*) { return true; }))
    if (sub->get_name() == word) return sub;
  return nullptr;
}

// " (did you mean 'x'?)" for the closest of `names` fewer than `limit` edits away, else "".
std::string did_you_mean(const std::string& word, const std::vector<std::string>& names, size_t limit) {
  std::string hint;
  for (const std::string& n : names) {
    const size_t d = nsg::options::edit_distance(word, n);
    if (d < limit) {
      limit = d;
      hint = " (did you mean '" + n + "'?)";
    }
  }
  return hint;
}

// The first word that is not a global flag names the command. Checked before CLI11 parses:
// with an unknown command CLI11 would treat the rest as extras and act on global flags
// among them (`nsgraph generat --version v1.0-mini` printed the program version, exit 0).
// The global options are flags only, so no word before the command is an option's value.
bool check_command_word(CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    if (!word.empty() && word[0] == '-') continue;
    const std::vector<std::string> names = command_names(app);
    if (std::find(names.begin(), names.end(), word) != names.end()) return true;
    const std::string hint = did_you_mean(word, names, 3);  // only close names
    std::string list;
    for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
    std::fprintf(stderr, "nsgraph: error: unknown command '%s'%s\ncommands: %s\nRun 'nsgraph --help' for more.\n",
                 word.c_str(), hint.c_str(), list.c_str());
    return false;
  }
  return true;
}

// `--version` after a command that reads no release would fall through to the program's
// flag: `nsgraph score ... --version v1.0-mini` printed "nsgraph 0.1.0", exit 0, and wrote
// nothing. The program's version is asked before any command; after one, --version is
// the command's own option or refused by name.
bool check_version_flag(CLI::App& app, int argc, char** argv) {
  CLI::App* command = nullptr;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    if (word == "--version" || word.starts_with("--version=")) {
      if (command == nullptr || command->get_option_no_throw("--version") != nullptr) continue;
      // `frames` reads the release its dataset was generated from, of the manifest's version.
      const char* why = path == "frames" ? "this command reads the release of its --dataset, of the version the "
                                           "dataset's manifest names"
                                         : "this command reads no nuScenes release";
      std::fprintf(stderr,
                   "nsgraph: error: %s: --version: %s, so it takes no release version; the program's version is "
                   "'nsgraph --version' (before any command)\n",
                   path.c_str(), why);
      return false;
    }
    if (word.empty() || word[0] == '-') continue;
    // A word naming a subcommand of the current command descends into it; any other word
    // is an option's value or a positional argument.
    if (CLI::App* sub = subcommand_named(command != nullptr ? *command : app, word)) {
      command = sub;
      path += (path.empty() ? "" : " ") + word;
    }
  }
  return true;
}

// A mistyped option gets the option it was probably meant to be, like commands and config
// keys: CLI11 alone says "The following arguments were not expected: 2 --thread", and only
// after any missing required option. Checked before parsing, against the options of the
// command named so far and of the commands above it (global flags fall through).
bool check_option_words(CLI::App& app, int argc, char** argv) {
  CLI::App* command = &app;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word == "--") break;
    if (!word.starts_with("--")) {
      if (CLI::App* sub = subcommand_named(*command, word)) {
        command = sub;
        path += (path.empty() ? "" : " ") + word;
      }
      continue;
    }
    const std::string name = word.substr(0, word.find('='));
    std::vector<std::string> known;  // every long name in reach, "--threads"
    bool found = false;
    for (CLI::App* at = command; at != nullptr && !found; at = at->get_parent()) {
      for (const CLI::Option* opt : at->get_options()) {
        if (opt->check_name(name)) found = true;
        for (const std::string& l : opt->get_lnames()) known.push_back("--" + l);
      }
    }
    if (found) continue;
    const std::string hint = did_you_mean(name, known, std::max<size_t>(3, name.size() / 4));  // only close names
    const std::string where = path.empty() ? "nsgraph" : "nsgraph " + path;
    std::fprintf(stderr, "nsgraph: error: %s: unknown option '%s'%s\nRun '%s --help' for its options.\n",
                 path.empty() ? "nsgraph" : path.c_str(), name.c_str(), hint.c_str(), where.c_str());
    return false;
  }
  return true;
}

int run(int argc, char** argv) {
  CLI::App app{"nsgraph — build, validate and score the NuScenesGraph lane-graph benchmark"};
  app.set_version_flag("--version", std::string("nsgraph ") + nsg::kVersion);
  app.require_subcommand(1);
  app.fallthrough();  // global flags are accepted after the command name too
  nsg::cli::Context ctx;
  app.add_flag("-q,--quiet", ctx.quiet, "Only errors on stderr");
  app.add_flag("-v,--verbose", ctx.verbose, "Debug log lines");
  for (nsg::cli::AddCommand add : kCommands) add(app, ctx);
  if (!check_command_word(app, argc, argv) || !check_version_flag(app, argc, argv) ||
      !check_option_words(app, argc, argv))
    return nsg::kExitInput;
  if (argc == 1) {  // a bare `nsgraph`: the commands there are, not only "a subcommand is required"
    std::fprintf(stderr, "%s\nnsgraph: error: no command given (one of those above; `nsgraph <command> --help`)\n",
                 app.help().c_str());
    return nsg::kExitInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // prints help/version or the usage error
    return code == 0 ? nsg::kExitOk : nsg::kExitInput;
  }
  if (ctx.quiet) nsg::log::set_level(nsg::log::Level::kError);
  if (ctx.verbose) nsg::log::set_level(nsg::log::Level::kDebug);
  if (!ctx.run) throw nsg::InternalError("", "", "command selected without a runner");
  return ctx.run();
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const nsg::Error& e) {
    std::fprintf(stderr, "nsgraph: error: %s\n", e.what());
    return e.exit_code();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "nsgraph: error: out of memory\n");
    return nsg::kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "nsgraph: internal error: %s\n", e.what());
    return nsg::kExitInternal;
  }
}
