// fsmbt_lebt_driver: run an LEBT written by `fsmbt convert` in BehaviorTree.CPP v4 through
// fsmbt/lebt.hpp, reading events from stdin and printing what each macro step did.
//
//   fsmbt_lebt_driver TREE.xml [--start NAME] [--register A,B,...] [--table] [--bench R]
//                              [--tick once|exactly-once|auto] [--entries]
//                              [--btlog FILE.btlog] [--db3 FILE.db3]
//   fsmbt_lebt_driver TREE.xml --scripted SEED [--ticks N] [--conditions A,B] [--actions C,D]
//                              [--btlog FILE.btlog] [--db3 FILE.db3]
//   fsmbt_lebt_driver --version
//
// Input (stdin): one event name per line (a trailing '\r' is dropped; empty lines are skipped).
// The line `%reset` puts the run back to before its start (the tree is halted) and starts again,
// so one process can replay many event sequences.
//
// Output (stdout): one JSON object per line - the start, then one per event:
//   {"step":0,"event":null,"actions":["A"],"terminated":false,"state":"A"}
//   {"step":1,"event":"go","actions":["B"],"terminated":true,"state":"B"}
// `step` counts events since the last start. Errors go to stderr as one line
// `error: ...` with exit status 1 (load errors: unknown leaf with its line, missing callbacks).
//
// Options:
//   --start NAME     the start pseudo-state (default: inferred, docs/semantics.md section 5)
//   --register LIST  register callbacks only for these comma-separated action names (each one
//                    records its call); without it every action gets a recording fallback. An
//                    action of the tree missing from LIST is a load-time error.
//   --tick MODE      how the root is ticked (fsmbt::lebt::TickMode; default auto)
//   --entries        every action callback prints the state and parameters it received, one
//                    JSON line {"entered":STATE,"params":{...}} before its step's line
//   --table          run the same FSM as a plain transition table read off the tree's guards and
//                    states (no behavior tree ticks): the baseline of benchmarks/bench_runtime.py
//   --dispatch       require the dispatch form of `fsmbt convert --style dispatch`
//                    (docs/semantics.md section 12; LebtRunner detects the form by itself: a tree
//                    of DispatchEntry leaves runs as one, each step writes {event} and ticks the
//                    root once); an LEBT is then refused
//   --bench R        read all of stdin first, replay it R times without printing steps, then print
//                    one JSON object: {"mode","steps","seconds","ns_per_step","cpu_seconds",
//                    "cpu_ns_per_step","leaf_ticks","actions"} (wall clock and process CPU time)
//   --btlog FILE     log every status transition of the tree with BehaviorTree.CPP's FileLogger2
//                    (the .btlog `fsmbt conform` reads; docs/conform.md), written by the end
//   --db3 FILE       the same with BehaviorTree.CPP's SqliteLogger (FILE must end in .db3; needs
//                    a BehaviorTree.CPP built with BTCPP_SQLITE_LOGGING, else exit 1). 4.8.2's
//                    SqliteLogger drops the transitions its writer thread has not stored when it is
//                    destroyed, so the driver waits (polling the file, at most 60 s) until the
//                    table holds every transition the logger was given; it turns SQLite's
//                    `synchronous` off for the file (one commit per transition otherwise syncs
//                    the disk each time) and sets a busy timeout, which change no content.
//                    Its destructor can also hang for ever (a lost wakeup, see
//                    CountingSqliteLogger::finish), so once every row is stored the driver
//                    disables the logger and never destroys it: the rows are committed, the
//                    process exit closes the file.
//
// Scripted mode (any BehaviorTree.CPP v4 tree, not only an LEBT; no stdin):
//   --scripted SEED  every leaf type named in --conditions (returns SUCCESS or FAILURE) and
//                    --actions (a stateful action: SUCCESS, FAILURE or RUNNING, also when ticked
//                    again while RUNNING) draws its outcome from one std::mt19937(SEED), uniformly;
//                    the root is ticked --ticks times (default 30) with tickOnce, and each tick
//                    prints {"tick":I,"status":"SUCCESS"|"FAILURE"|"RUNNING"}. The loggers above
//                    record the run: the logs `fsmbt conform` checks in the tests.
#include <fsmbt/lebt.hpp>

#include <behaviortree_cpp/loggers/bt_file_logger_v2.h>
#include <behaviortree_cpp/xml_parsing.h>
#if __has_include(<behaviortree_cpp/loggers/bt_sqlite_logger.h>)
#include <behaviortree_cpp/loggers/bt_sqlite_logger.h>
#include <sqlite3.h>
#define FSMBT_HAS_SQLITE_LOGGER 1
#endif

#include <atomic>
#include <filesystem>
#include <chrono>
#include <thread>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace {

constexpr const char* kReset = "%reset";

std::string jsonString(const std::string& text)
{
  std::string out = "\"";
  for(unsigned char ch : text)
  {
    switch(ch)
    {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if(ch < 0x20)
        {
          char buffer[8];
          std::snprintf(buffer, sizeof buffer, "\\u%04x", ch);
          out += buffer;
        }
        else
        {
          out.push_back(static_cast<char>(ch));
        }
    }
  }
  return out + "\"";
}

void printStep(long step, const std::string* event, const fsmbt::lebt::StepResult& result)
{
  std::string line = "{\"step\":" + std::to_string(step) +
                     ",\"event\":" + (event ? jsonString(*event) : std::string("null")) +
                     ",\"actions\":[";
  for(std::size_t i = 0; i < result.actions.size(); ++i)
  {
    line += (i ? "," : "") + jsonString(result.actions[i]);
  }
  line += std::string("],\"terminated\":") + (result.terminated ? "true" : "false") +
          ",\"state\":" + jsonString(result.state) + "}\n";
  std::fputs(line.c_str(), stdout);
}

/// The FSM the LEBT encodes, as a plain table: state index -> (event -> target index). Built
/// from the loaded runner's leaves: each atomic state's own guard (target = a state) holds the
/// (source, event) pairs entering it; cluster guards (target = a composite path) are skipped.
class TableRunner
{
public:
  explicit TableRunner(const fsmbt::lebt::LebtRunner& lebt) : start_(lebt.startState())
  {
    for(const fsmbt::lebt::LebtState* leaf : lebt.states())
    {
      if(ids_.count(leaf->stateName()) == 0)
      {
        ids_[leaf->stateName()] = static_cast<int>(names_.size());
        names_.push_back(leaf->stateName());
        actions_.push_back(leaf->actionName());
        finals_.push_back(leaf->isFinal());
      }
    }
    table_.resize(names_.size());
    for(const fsmbt::lebt::LebtGuard* guard : lebt.guards())
    {
      auto target = ids_.find(guard->target());
      if(target == ids_.end())
      {
        continue;  // a composite state's guard: its pairs reappear at the atomic targets
      }
      for(const auto& [source, event] : guard->pairs())
      {
        if(source == start_)
        {
          (event.empty() ? init_target_ : start_events_[event]) = target->second;
          continue;
        }
        auto from = ids_.find(source);
        if(from == ids_.end())
        {
          throw fsmbt::lebt::LebtError("guard pair " + source + "/" + event +
                                       " leaves an unknown state");
        }
        auto [it, inserted] = table_[from->second].emplace(event, target->second);
        if(!inserted && it->second != target->second)
        {
          throw fsmbt::lebt::LebtError("two targets for " + source + "/" + event);
        }
      }
    }
  }

  fsmbt::lebt::StepResult start()
  {
    current_ = -1;
    actions_run_.clear();
    if(init_target_ >= 0)
    {
      enter(init_target_);
    }
    return result();
  }

  fsmbt::lebt::StepResult post(const std::string& event)
  {
    actions_run_.clear();
    if(current_ < 0)
    {
      auto it = start_events_.find(event);
      if(it != start_events_.end())
      {
        enter(it->second);
      }
    }
    else if(!finals_[current_])
    {
      const auto& row = table_[current_];
      auto it = row.find(event);
      if(it != row.end())
      {
        enter(it->second);
      }
    }
    return result();
  }

private:
  void enter(int target)
  {
    current_ = target;
    if(!actions_[target].empty())
    {
      actions_run_.push_back(actions_[target]);
    }
  }

  fsmbt::lebt::StepResult result() const
  {
    const bool final = current_ >= 0 && finals_[current_];
    return { actions_run_, final, current_ < 0 ? start_ : names_[current_] };
  }

  std::string start_;
  std::unordered_map<std::string, int> ids_;
  std::vector<std::string> names_;
  std::vector<std::string> actions_;
  std::vector<bool> finals_;
  std::vector<std::unordered_map<std::string, int>> table_;
  std::unordered_map<std::string, int> start_events_;
  int init_target_ = -1;
  int current_ = -1;
  std::vector<std::string> actions_run_;
};

struct Arguments
{
  bool dispatch = false;
  std::string tree;
  std::optional<std::string> start;
  std::optional<std::vector<std::string>> registered;
  bool table = false;
  bool entries = false;
  long bench = 0;
  fsmbt::lebt::TickMode tick = fsmbt::lebt::TickMode::Auto;
  std::optional<std::string> btlog;
  std::optional<std::string> db3;
  std::optional<unsigned long> scripted;
  long ticks = 30;
  std::vector<std::string> conditions;
  std::vector<std::string> actions;
};

std::vector<std::string> splitList(const std::string& text)
{
  std::vector<std::string> names;
  std::stringstream list(text);
  for(std::string name; std::getline(list, name, ',');)
  {
    if(!name.empty())
    {
      names.push_back(name);
    }
  }
  return names;
}

[[noreturn]] void usage(const std::string& problem)
{
  std::fprintf(stderr,
               "error: %s\nusage: fsmbt_lebt_driver TREE.xml [--start NAME] [--register A,B] "
               "[--table] [--entries] [--bench R] [--tick once|exactly-once|auto] "
               "[--btlog FILE] [--db3 FILE] [--scripted SEED [--ticks N] [--conditions A,B] "
               "[--actions C,D]] | --version\n",
               problem.c_str());
  std::exit(2);
}

Arguments parse(int argc, char** argv)
{
  Arguments args;
  for(int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if(i + 1 >= argc)
      {
        usage(arg + " needs a value");
      }
      return argv[++i];
    };
    if(arg == "--start")
    {
      args.start = value();
    }
    else if(arg == "--register")
    {
      std::vector<std::string> names;
      std::stringstream list(value());
      for(std::string name; std::getline(list, name, ',');)
      {
        if(!name.empty())
        {
          names.push_back(name);
        }
      }
      args.registered = names;
    }
    else if(arg == "--tick")
    {
      const std::string mode = value();
      if(mode == "once")
      {
        args.tick = fsmbt::lebt::TickMode::Once;
      }
      else if(mode == "exactly-once")
      {
        args.tick = fsmbt::lebt::TickMode::ExactlyOnce;
      }
      else if(mode == "auto")
      {
        args.tick = fsmbt::lebt::TickMode::Auto;
      }
      else
      {
        usage("--tick takes once, exactly-once or auto");
      }
    }
    else if(arg == "--dispatch")
    {
      args.dispatch = true;
    }
    else if(arg == "--table")
    {
      args.table = true;
    }
    else if(arg == "--btlog")
    {
      args.btlog = value();
    }
    else if(arg == "--db3")
    {
      args.db3 = value();
    }
    else if(arg == "--scripted" || arg == "--ticks")
    {
      long number = -1;
      try
      {
        number = std::stol(value());
      }
      catch(const std::exception&)
      {
      }
      if(number < 0)
      {
        usage(arg + " needs a number >= 0");
      }
      if(arg == "--ticks")
      {
        args.ticks = number;
      }
      else
      {
        args.scripted = static_cast<unsigned long>(number);
      }
    }
    else if(arg == "--conditions")
    {
      args.conditions = splitList(value());
    }
    else if(arg == "--actions")
    {
      args.actions = splitList(value());
    }
    else if(arg == "--entries")
    {
      args.entries = true;
    }
    else if(arg == "--bench")
    {
      try
      {
        args.bench = std::stol(value());
      }
      catch(const std::exception&)
      {
        usage("--bench needs a number of repetitions");
      }
      if(args.bench < 1)
      {
        usage("--bench needs a number of repetitions >= 1");
      }
    }
    else if(!arg.empty() && arg[0] == '-')
    {
      usage("unknown option " + arg);
    }
    else if(args.tree.empty())
    {
      args.tree = arg;
    }
    else
    {
      usage("one tree file only");
    }
  }
  if(args.tree.empty())
  {
    usage("no tree file given");
  }
  return args;
}

std::vector<std::string> readLines()
{
  std::vector<std::string> lines;
  for(std::string line; std::getline(std::cin, line);)
  {
    if(!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    if(!line.empty())
    {
      lines.push_back(line);
    }
  }
  return lines;
}

/// Run `lines` through `runner` (LebtRunner or TableRunner), printing every step.
template <typename Runner>
void interactive(Runner& runner, fsmbt::lebt::LebtRunner* lebt)
{
  long step = 0;
  printStep(step, nullptr, runner.start());
  for(std::string line; std::getline(std::cin, line);)
  {
    if(!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    if(line.empty())
    {
      continue;
    }
    if(line == kReset)
    {
      if(lebt != nullptr)
      {
        lebt->reset();
      }
      step = 0;
      printStep(step, nullptr, runner.start());
      continue;
    }
    printStep(++step, &line, runner.post(line));
  }
  std::fflush(stdout);
}

/// Replay `lines` `repeat` times; only the post() calls are timed.
template <typename Runner>
void bench(Runner& runner, fsmbt::lebt::LebtRunner* lebt, const std::vector<std::string>& lines,
           long repeat, const char* mode)
{
  using Clock = std::chrono::steady_clock;
  Clock::duration spent{};
  double cpu_spent = 0.0;  // process CPU time: what the steps cost without waiting for a core
  auto cpu_now = []() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
  };
  std::size_t sink = 0;  // keeps the results observable
  const std::uint64_t ticks_before = lebt != nullptr && mode[0] != 't' ? lebt->leafTicks() : 0;
  for(long r = 0; r < repeat; ++r)
  {
    if(lebt != nullptr)
    {
      lebt->reset();
    }
    runner.start();
    std::size_t i = 0;
    while(i < lines.size())
    {
      if(lines[i] == kReset)
      {
        if(lebt != nullptr)
        {
          lebt->reset();
        }
        runner.start();
        ++i;
        continue;
      }
      std::size_t end = i;
      while(end < lines.size() && lines[end] != kReset)
      {
        ++end;
      }
      const auto t0 = Clock::now();
      const double c0 = cpu_now();
      for(; i < end; ++i)
      {
        sink += runner.post(lines[i]).actions.size();
      }
      cpu_spent += cpu_now() - c0;
      spent += Clock::now() - t0;
    }
  }
  long steps = 0;
  for(const std::string& line : lines)
  {
    steps += line != kReset;
  }
  steps *= repeat;
  const double seconds = std::chrono::duration<double>(spent).count();
  const std::uint64_t ticks =
      (lebt != nullptr && mode[0] != 't' ? lebt->leafTicks() : 0) - ticks_before;
  const double per = steps ? 1e9 / static_cast<double>(steps) : 0.0;
  std::printf("{\"mode\":\"%s\",\"steps\":%ld,\"seconds\":%.9f,\"ns_per_step\":%.1f,"
              "\"cpu_seconds\":%.9f,\"cpu_ns_per_step\":%.1f,\"leaf_ticks\":%llu,"
              "\"actions\":%zu}\n",
              mode, steps, seconds, seconds * per, cpu_spent, cpu_spent * per,
              static_cast<unsigned long long>(ticks), sink);
}

/// BehaviorTree.CPP's FileLogger2 that counts the transitions it is given. 4.8.2's destructor
/// stops the writer thread, which drops what it has not taken from its queue (everything when it
/// has not run yet, on a loaded machine), so this waits until the file is as long as the header
/// (magic, protocol, length, WriteTreeToXML(tree, true, true), first time stamp) plus 9 bytes per
/// transition given (at most 60 s; then a warning on stderr).
class CountingFileLogger2 : public BT::FileLogger2
{
public:
  CountingFileLogger2(const BT::Tree& tree, const std::string& path)
    : BT::FileLogger2(tree, path)
    , path_(path)
    , header_(18 + 1 + 4 + BT::WriteTreeToXML(tree, true, true).size() + 8)
  {}

  ~CountingFileLogger2() override { waitWritten(); }

  void callback(BT::Duration timestamp, const BT::TreeNode& node, BT::NodeStatus prev_status,
                BT::NodeStatus status) override
  {
    ++given_;
    BT::FileLogger2::callback(timestamp, node, prev_status, status);
  }

private:
  void waitWritten() const
  {
    const std::uintmax_t want = header_ + 9 * static_cast<std::uintmax_t>(given_.load());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    std::uintmax_t size = 0;
    while(std::chrono::steady_clock::now() < deadline)
    {
      std::error_code error;
      size = std::filesystem::file_size(path_, error);
      if(!error && size >= want)
      {
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    std::fprintf(stderr, "warning: the .btlog holds %ju of %ju bytes\n", size, want);
  }

  std::string path_;
  std::uintmax_t header_;
  std::atomic<long> given_{ 0 };
};

#ifdef FSMBT_HAS_SQLITE_LOGGER
/// BehaviorTree.CPP's SqliteLogger that counts the transitions it is given (all from the thread
/// that ticks the tree).
class CountingSqliteLogger : public BT::SqliteLogger
{
public:
  CountingSqliteLogger(const BT::Tree& tree, const std::string& path)
    : BT::SqliteLogger(tree, path), path_(path)
  {
    execSqlStatement("PRAGMA synchronous = OFF;");
    // the writer waits for waitStored()'s reads instead of failing with SQLITE_BUSY
    execSqlStatement("PRAGMA busy_timeout = 10000;");
  }

  /// End the log: wait until every transition given is stored, then stop logging. Call it, then
  /// leave the object alive until the process exits (Loggers does): BehaviorTree.CPP 4.8.2's
  /// ~SqliteLogger stores `loop_ = false` and notifies its writer without holding the queue
  /// mutex, so a writer between its wait predicate and its wait misses the wakeup and the
  /// destructor's join() never returns (a CI run of test_mutants_db3_logs_against_the_source
  /// timed out so under load). Every row is committed by then (one autocommit per INSERT), so
  /// skipping the destructor loses nothing but its `PRAGMA optimize`.
  void finish()
  {
    waitStored();
    setEnabled(false);  // halts at the tree's destruction are not logged, as before
  }

  void callback(BT::Duration timestamp, const BT::TreeNode& node, BT::NodeStatus prev_status,
                BT::NodeStatus status) override
  {
    ++given_;
    BT::SqliteLogger::callback(timestamp, node, prev_status, status);
  }

private:
  /// Poll the file (a second, read-only connection) until its Transitions table holds every
  /// transition given; the base destructor then stops the writer with nothing left to drop.
  void waitStored() const
  {
    sqlite3* db = nullptr;
    if(sqlite3_open_v2(path_.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK)
    {
      sqlite3_close(db);
      return;
    }
    sqlite3_busy_timeout(db, 1000);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    long stored = -1;
    while(std::chrono::steady_clock::now() < deadline)
    {
      sqlite3_stmt* stmt = nullptr;
      if(sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM Transitions", -1, &stmt, nullptr) ==
             SQLITE_OK &&
         sqlite3_step(stmt) == SQLITE_ROW)
      {
        stored = sqlite3_column_int64(stmt, 0);
      }
      sqlite3_finalize(stmt);
      if(stored >= given_)
      {
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    sqlite3_close(db);
    if(stored < given_)
    {
      std::fprintf(stderr, "warning: the SQLite log holds %ld of %ld transitions\n", stored,
                   static_cast<long>(given_));
    }
  }

  std::string path_;
  std::atomic<long> given_{ 0 };
};
#endif

/// The loggers --btlog and --db3 ask for, attached to `tree` while this object lives (destroy it
/// before the tree: each destructor writes what is left; the SQLite logger is finished and then
/// deliberately left alive until the process exits, see CountingSqliteLogger::finish).
class Loggers
{
public:
  Loggers(const BT::Tree& tree, const Arguments& args)
  {
    if(args.btlog)
    {
      file_ = std::make_unique<CountingFileLogger2>(tree, *args.btlog);
    }
    if(args.db3)
    {
#ifdef FSMBT_HAS_SQLITE_LOGGER
      sqlite_ = std::make_unique<CountingSqliteLogger>(tree, *args.db3);
#else
      throw std::runtime_error("--db3: this BehaviorTree.CPP was built without its SQLite logger "
                               "(BTCPP_SQLITE_LOGGING=OFF); rebuild with scripts/build_btcpp.sh");
#endif
    }
  }

  Loggers(const Loggers&) = delete;
  Loggers& operator=(const Loggers&) = delete;

  ~Loggers()
  {
#ifdef FSMBT_HAS_SQLITE_LOGGER
    if(sqlite_)
    {
      sqlite_->finish();
      static_cast<void>(sqlite_.release());  // left alive on purpose: see finish()
    }
#endif
  }

private:
  std::unique_ptr<CountingFileLogger2> file_;
#ifdef FSMBT_HAS_SQLITE_LOGGER
  std::unique_ptr<CountingSqliteLogger> sqlite_;
#endif
};

/// A scripted action of --scripted: SUCCESS, FAILURE or RUNNING drawn from the shared generator
/// at every tick (the first and each one while RUNNING).
class ScriptedAction : public BT::StatefulActionNode
{
public:
  ScriptedAction(const std::string& name, const BT::NodeConfig& config, std::mt19937& rng)
    : BT::StatefulActionNode(name, config), rng_(rng)
  {}

  BT::NodeStatus onStart() override { return draw(); }
  BT::NodeStatus onRunning() override { return draw(); }
  void onHalted() override {}

private:
  BT::NodeStatus draw()
  {
    static constexpr BT::NodeStatus kOutcomes[] = { BT::NodeStatus::SUCCESS,
                                                    BT::NodeStatus::FAILURE,
                                                    BT::NodeStatus::RUNNING };
    return kOutcomes[std::uniform_int_distribution<int>(0, 2)(rng_)];
  }

  std::mt19937& rng_;
};

/// --scripted: load any tree with the listed leaves scripted, tick it, print each root status.
void scripted(const Arguments& args)
{
  std::mt19937 rng(static_cast<std::mt19937::result_type>(*args.scripted));
  BT::BehaviorTreeFactory factory;
  for(const std::string& name : args.conditions)
  {
    factory.registerSimpleCondition(name, [&rng](BT::TreeNode&) {
      return std::uniform_int_distribution<int>(0, 1)(rng) == 0 ? BT::NodeStatus::SUCCESS :
                                                                   BT::NodeStatus::FAILURE;
    });
  }
  for(const std::string& name : args.actions)
  {
    factory.registerBuilder<ScriptedAction>(
        name, [&rng](const std::string& instance, const BT::NodeConfig& config) {
          return std::make_unique<ScriptedAction>(instance, config, rng);
        });
  }
  BT::Tree tree = factory.createTreeFromFile(args.tree);
  {
    Loggers loggers(tree, args);
    for(long i = 1; i <= args.ticks; ++i)
    {
      const BT::NodeStatus status = tree.tickOnce();
      std::printf("{\"tick\":%ld,\"status\":%s}\n", i,
                  jsonString(BT::toStr(status, false)).c_str());
    }
  }  // the loggers write the rest of the log here, before the tree goes
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv)
{
  std::ios::sync_with_stdio(false);
  if(argc == 2 && std::string(argv[1]) == "--version")
  {
    std::printf("%s on BehaviorTree.CPP %s\n", fsmbt::lebt::kRuntimeVersion,
                BT::LibraryVersionString());
    return 0;
  }
  const Arguments args = parse(argc, argv);
  try
  {
    if(args.scripted)
    {
      scripted(args);
      return 0;
    }
    fsmbt::lebt::ActionRegistry actions;
    // --entries: each callback prints what it received, {"entered":STATE,"params":{...}}
    auto callback = [entries = args.entries](const std::string& state,
                                             const fsmbt::lebt::Parameters& params) {
      if(!entries)
      {
        return;
      }
      std::string line = "{\"entered\":" + jsonString(state) + ",\"params\":{";
      bool first = true;
      for(const auto& [name, value] : params)
      {
        line += (first ? "" : ",") + jsonString(name) + ":" + jsonString(value);
        first = false;
      }
      line += "}}\n";
      std::fputs(line.c_str(), stdout);
    };
    if(args.registered)
    {
      for(const std::string& name : *args.registered)
      {
        actions.add(name, callback);
      }
    }
    else
    {
      actions.addFallback(callback);
    }
    fsmbt::lebt::Options options;
    options.start = args.start;
    options.tick = args.tick;
    fsmbt::lebt::LebtRunner runner =
        fsmbt::lebt::LebtRunner::fromFile(args.tree, std::move(actions), options);
    if(args.dispatch && runner.form() != fsmbt::lebt::Form::Dispatch)
    {
      throw fsmbt::lebt::LebtError("--dispatch: " + args.tree +
                                   " is an LEBT, not the dispatch form (DispatchEntry leaves)");
    }
    Loggers loggers(runner.tree(), args);  // after the runner: destroyed (and written) first
    if(args.table)
    {
      TableRunner table(runner);
      if(args.bench > 0)
      {
        bench(table, nullptr, readLines(), args.bench, "table");
      }
      else
      {
        interactive(table, nullptr);
      }
    }
    else if(args.bench > 0)
    {
      const bool dispatch = runner.form() == fsmbt::lebt::Form::Dispatch;
      bench(runner, &runner, readLines(), args.bench, dispatch ? "dispatch" : "bt");
    }
    else
    {
      interactive(runner, &runner);
    }
  }
  catch(const std::exception& exc)
  {
    std::fflush(stdout);
    std::fprintf(stderr, "error: %s\n", exc.what());
    return 1;
  }
  return 0;
}
