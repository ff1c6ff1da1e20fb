// fsmbt runtime for BehaviorTree.CPP v4 (header-only; C++17).
//
// Runs the two forms of tree `fsmbt convert` writes from an event-driven state machine, through
// one API (LebtRunner, ActionRegistry, StepResult), the form told from the tree's leaves:
//  - the dispatch form (the default style; docs/semantics.md section 12): a Switch dispatch over
//    a state index on the blackboard, one leaf type, `DispatchEntry` - see "the dispatch form"
//    below, and LebtRunner::checkDispatch for the annotations checked at load time;
//  - the loop-execution behavior tree (LEBT, `--style lebt`): leaves `LebtGuard` and
//    `LebtState`, meaning docs/semantics.md section 5 ("The LEBT protocol"), which this file
//    follows literally:
//
//  - blackboard: `state` (starts at the start pseudo-state) and `event` ("" = none). Both live in
//    a `fsmbt::lebt::Context` owned by the runner and shared by every leaf of the tree, SubTrees
//    included, so a hierarchical conversion (one <BehaviorTree> per composite state, <SubTree>
//    references, no port remapping) runs unchanged.
//  - LebtGuard (a Condition; ports `target`, `pairs`): FAILURE when (state, event) is one of its
//    `source/event` pairs (the transition fires), else SUCCESS. `Start/` (empty event) is the
//    initialisation pair.
//  - LebtState (a stateful Action; ports `state`, `action`, `final`, `exits` and the optional
//    `params`, `name=value;...`): onStart runs the state's action (the user's callback
//    registered under the action's name, called with the state's label and parameters; once
//    per entry),
//    sets `state`, clears `event`, returns RUNNING (SUCCESS when final). onRunning: SUCCESS when
//    the pending event has a transition out of the state (the event is kept), else the event is
//    dropped and the leaf stays RUNNING; RUNNING when no event is pending.
//  - macro step (LebtRunner::post): set `event`, tickOnce(); if the root returned SUCCESS with
//    the event still pending, tick once more; then drop any event still pending.
//  - tickOnce() vs tickExactlyOnce(): they differ only when a node emitted a wake-up signal
//    (docs/semantics.md section 3). When every node of the tree is one that never does
//    (Sequence, Fallback, SubTree, the LEBT leaves, ...: kNeverWakeUp) the runner calls
//    tickExactlyOnce(), which gives the same result and skips tickOnce()'s wake-up check - a
//    condition_variable wait with a zero timeout, one futex system call per RUNNING tick, which
//    costs microseconds and, on a busy machine, a reschedule (benchmarks/bench_runtime.py
//    measures both). Options::tick forces one or the other.
//  - start (LebtRunner::start): when a guard holds the pair (start, "") the root is ticked once
//    with no event so the initial state's action runs; otherwise nothing is ticked.
//  - start pseudo-state: the one guard source that is not a state, else "__start__" (or
//    Options::start).
//  - terminated: the last root result is SUCCESS and `state` is no longer the start
//    pseudo-state.
//
// The dispatch form (section 12): `DispatchEntry` runs its action's callback (state label and
// params, as LebtState) and returns SUCCESS, after which BehaviorTree.CPP runs its `_onSuccess`
// post-condition writing the entered state's index digits; start() ticks once with `event`
// unset, post(e) writes the blackboard entry `event` and ticks once; terminated = last root
// result SUCCESS. A step ticks O(log7 states + out-degree / 6) nodes.
//
// Load-time errors (fsmbt::lebt::LebtError, derived from std::runtime_error): a leaf the runtime
// does not define (BehaviorTree.CPP's "Error at line N: -> Node not recognized: X"), a port that
// is a blackboard reference or malformed, an action name with no registered callback, and LEBT
// annotations that contradict each other (a guard pair whose event is not an exit of its source
// state, an exit no guard pair takes, a pair source that is neither a state nor the start
// pseudo-state: hand edits that would otherwise stop the machine silently), dispatch annotations
// that disagree (a malformed index digit, an index no state has, ...: checkDispatch) - all
// raised by the LebtRunner constructor, never at tick time, naming the node and its line.
//
// Cost: a guard tick is two hash look-ups, a state tick one. A macro step ticks from the root
// down to the running leaf (BehaviorTree.CPP resumes each Sequence at its running child, but every
// tick walks the path), and when the event leaves the running subtree for a selector of the root
// Sequence the second tick scans the root's selectors guard by guard: O(depth + root selectors)
// node ticks per step (benchmarks/bench_runtime.py: ~46 ns of CPU per level; docs/runtime.md).
//
// Usage:
//   fsmbt::lebt::ActionRegistry actions;
//   actions.add("Open", [](const std::string& state) { /* drive the motor */ });
//   fsmbt::lebt::LebtRunner runner = fsmbt::lebt::LebtRunner::fromFile("door.xml", actions);
//   runner.start();
//   fsmbt::lebt::StepResult r = runner.post("open_cmd");   // r.actions, r.terminated
#pragma once

#include <behaviortree_cpp/action_node.h>
#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/condition_node.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace fsmbt {
namespace lebt {

inline constexpr const char* kGuardType = "LebtGuard";
inline constexpr const char* kStateType = "LebtState";
inline constexpr const char* kDefaultStart = "__start__";
inline constexpr const char* kRuntimeVersion = "fsmbt-lebt 1.0";

/// Every load-time problem of a tree (LEBT or dispatch form): unknown leaves, bad ports, missing
/// action callbacks, annotations that disagree.
class LebtError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

// -- the escaping of fsmbt.semantics.lebt_spec: names with ';', '/' or '\' carry a backslash --
namespace detail {

/// Split `text` on unescaped `sep`; the parts keep their escapes.
inline std::vector<std::string> splitKeepingEscapes(std::string_view text, char sep)
{
  std::vector<std::string> parts;
  std::string current;
  bool escaped = false;
  for(char ch : text)
  {
    if(escaped)
    {
      current.push_back('\\');
      current.push_back(ch);
      escaped = false;
    }
    else if(ch == '\\')
    {
      escaped = true;
    }
    else if(ch == sep)
    {
      parts.push_back(std::move(current));
      current.clear();
    }
    else
    {
      current.push_back(ch);
    }
  }
  parts.push_back(std::move(current));
  return parts;
}

/// Drop the backslash escapes (a trailing lone backslash is dropped, as lebt_spec does).
inline std::string unescape(std::string_view text)
{
  std::string out;
  out.reserve(text.size());
  for(std::size_t i = 0; i < text.size(); ++i)
  {
    if(text[i] == '\\')
    {
      if(i + 1 < text.size())
      {
        out.push_back(text[++i]);
      }
    }
    else
    {
      out.push_back(text[i]);
    }
  }
  return out;
}

/// The literal value of an input port as written in the XML ("" when absent). A blackboard
/// reference ("{key}") is refused: an LEBT's ports are constants fixed by the converter.
inline std::string literalPort(const BT::NodeConfig& config, const std::string& node_name,
                               const char* type, const std::string& port)
{
  auto it = config.input_ports.find(port);
  if(it == config.input_ports.end())
  {
    return {};
  }
  if(BT::TreeNode::isBlackboardPointer(it->second))
  {
    throw LebtError(std::string("<") + type + " name=\"" + node_name + "\"> (" + config.path +
                    "): port '" + port + "' is a blackboard reference '" + it->second +
                    "'; an LEBT leaf needs the literal value fsmbt wrote");
  }
  return it->second;
}

}  // namespace detail

/// The (source, event) pairs of a guard's `pairs` port; throws std::invalid_argument on an item
/// that is not `a/b`.
inline std::vector<std::pair<std::string, std::string>> decodePairs(std::string_view text)
{
  std::vector<std::pair<std::string, std::string>> pairs;
  if(text.empty())
  {
    return pairs;
  }
  for(const std::string& item : detail::splitKeepingEscapes(text, ';'))
  {
    std::vector<std::string> pieces = detail::splitKeepingEscapes(item, '/');
    if(pieces.size() != 2)
    {
      throw std::invalid_argument("malformed pair '" + item + "': expected 'a/b'");
    }
    pairs.emplace_back(detail::unescape(pieces[0]), detail::unescape(pieces[1]));
  }
  return pairs;
}

/// The events of a state's `exits` port.
inline std::vector<std::string> decodeExits(std::string_view text)
{
  std::vector<std::string> exits;
  if(text.empty())
  {
    return exits;
  }
  for(const std::string& part : detail::splitKeepingEscapes(text, ';'))
  {
    exits.push_back(detail::unescape(part));
  }
  return exits;
}

/// A state's parameters (its `params` port): name -> literal value text.
using Parameters = std::map<std::string, std::string>;

/// The parameters of a state's `params` port (`name=value` items separated by `;`, escaped as
/// fsmbt.semantics.lebt.spec.encode_params does); throws std::invalid_argument on an item
/// without `=`.
inline Parameters decodeParams(std::string_view text)
{
  Parameters params;
  if(text.empty())
  {
    return params;
  }
  for(const std::string& item : detail::splitKeepingEscapes(text, ';'))
  {
    std::size_t eq = std::string::npos;
    for(std::size_t i = 0; i < item.size(); ++i)
    {
      if(item[i] == '\\')
      {
        ++i;
      }
      else if(item[i] == '=')
      {
        eq = i;
        break;
      }
    }
    if(eq == std::string::npos || eq == 0)
    {
      throw std::invalid_argument("malformed parameter '" + item + "': expected 'name=value'");
    }
    params[detail::unescape(item.substr(0, eq))] = detail::unescape(item.substr(eq + 1));
  }
  return params;
}

/// User code run when a state is entered: receives the (flat) name of the state entered and
/// its parameters.
using ActionCallback = std::function<void(const std::string& state, const Parameters& params)>;

/// The user's actions, by the action name the tree's `LebtState` leaves carry.
class ActionRegistry
{
public:
  /// Register `callback` for `action` (replaces an earlier registration of the same name).
  /// `callback` takes (state, params), or the state only (the earlier signature).
  template <typename Callback>
  ActionRegistry& add(const std::string& action, Callback callback)
  {
    callbacks_[action] = wrap(std::move(callback));
    return *this;
  }

  /// Run `callback` for every action that has no callback of its own (a logger, a test
  /// recorder). Without it, an unregistered action is a load-time error.
  template <typename Callback>
  ActionRegistry& addFallback(Callback callback)
  {
    fallback_ = wrap(std::move(callback));
    return *this;
  }

  /// A callback taking (state) or (state, params) as an ActionCallback.
  template <typename Callback>
  static ActionCallback wrap(Callback callback)
  {
    if constexpr(std::is_invocable_v<Callback&, const std::string&, const Parameters&>)
    {
      return ActionCallback(std::move(callback));
    }
    else
    {
      static_assert(std::is_invocable_v<Callback&, const std::string&>,
                    "an action callback takes (const std::string& state, const "
                    "fsmbt::lebt::Parameters& params) or (const std::string& state)");
      return [callback = std::move(callback)](const std::string& state,
                                              const Parameters&) mutable { callback(state); };
    }
  }

  /// The callback that runs for `action`, or nullptr.
  const ActionCallback* find(const std::string& action) const
  {
    auto it = callbacks_.find(action);
    if(it != callbacks_.end())
    {
      return &it->second;
    }
    return fallback_ ? &fallback_ : nullptr;
  }

private:
  std::unordered_map<std::string, ActionCallback> callbacks_;
  ActionCallback fallback_;
};

/// What the leaves share (docs/semantics.md section 5's blackboard) and what a step reports.
struct Context
{
  std::string state;                     ///< the current flat state (or the start pseudo-state)
  std::string event;                     ///< the pending event, "" = none
  std::vector<std::string> actions_run;  ///< action names run since the step began, in order
  const ActionRegistry* registry = nullptr;
  std::uint64_t leaf_ticks = 0;          ///< LEBT leaf ticks so far (a cost counter)
};

namespace detail {

/// The `params` port of a state leaf (`LebtState`, `DispatchEntry`) decoded; a malformed one
/// is a load error naming the leaf.
inline Parameters paramsPort(const BT::NodeConfig& config, const std::string& name,
                             const char* type)
{
  try
  {
    return decodeParams(literalPort(config, name, type, "params"));
  }
  catch(const std::invalid_argument& exc)
  {
    throw LebtError(std::string("<") + type + " name=\"" + name + "\"> (" + config.path +
                    "): port 'params': " + exc.what());
  }
}

/// A state leaf's entry, the same in both forms: count the leaf tick, run the state's action
/// (recorded, and the user's callback with the state's label and parameters when one is
/// bound), make the state current.
inline void enterState(Context& context, const std::string& state, const std::string& action,
                       const Parameters& params, const ActionCallback* callback)
{
  ++context.leaf_ticks;
  if(!action.empty())
  {
    context.actions_run.push_back(action);
    if(callback != nullptr)
    {
      (*callback)(state, params);
    }
  }
  context.state = state;
}

}  // namespace detail

/// `LebtGuard`: FAILURE when (state, event) is one of its pairs, else SUCCESS.
class LebtGuard : public BT::ConditionNode
{
public:
  LebtGuard(const std::string& name, const BT::NodeConfig& config, Context* context)
    : BT::ConditionNode(name, config), context_(context)
  {
    target_ = detail::literalPort(config, name, kGuardType, "target");
    const std::string raw = detail::literalPort(config, name, kGuardType, "pairs");
    try
    {
      for(auto& [source, event] : decodePairs(raw))
      {
        sources_by_event_[event].insert(source);
        pairs_.emplace_back(std::move(source), std::move(event));
      }
    }
    catch(const std::invalid_argument& exc)
    {
      throw LebtError(std::string("<LebtGuard name=\"") + name + "\"> (" + config.path +
                      "): " + exc.what());
    }
  }

  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("target", "the state this guard enters"),
             BT::InputPort<std::string>("pairs", "source/event pairs entering the target") };
  }

  /// True when the guard's transition fires for (state, event).
  bool matches(const std::string& state, const std::string& event) const
  {
    auto it = sources_by_event_.find(event);
    return it != sources_by_event_.end() && it->second.count(state) != 0;
  }

  const std::string& target() const { return target_; }
  const std::vector<std::pair<std::string, std::string>>& pairs() const { return pairs_; }

protected:
  BT::NodeStatus tick() override
  {
    ++context_->leaf_ticks;
    return matches(context_->state, context_->event) ? BT::NodeStatus::FAILURE :
                                                       BT::NodeStatus::SUCCESS;
  }

private:
  Context* context_;
  std::string target_;
  std::vector<std::pair<std::string, std::string>> pairs_;
  std::unordered_map<std::string, std::unordered_set<std::string>> sources_by_event_;
};

/// `LebtState`: enters its state on the first tick, then watches the pending event.
class LebtState : public BT::StatefulActionNode
{
public:
  LebtState(const std::string& name, const BT::NodeConfig& config, Context* context)
    : BT::StatefulActionNode(name, config), context_(context)
  {
    state_ = detail::literalPort(config, name, kStateType, "state");
    action_ = detail::literalPort(config, name, kStateType, "action");
    const std::string final_text = detail::literalPort(config, name, kStateType, "final");
    if(final_text == "true" || final_text == "True" || final_text == "TRUE")
    {
      final_ = true;
    }
    else if(!final_text.empty() && final_text != "false" && final_text != "False" &&
            final_text != "FALSE")
    {
      throw LebtError(std::string("<LebtState name=\"") + name + "\"> (" + config.path +
                      "): port 'final' is '" + final_text + "', expected true or false");
    }
    for(std::string& exit : decodeExits(detail::literalPort(config, name, kStateType, "exits")))
    {
      exits_.insert(std::move(exit));
    }
    params_ = detail::paramsPort(config, name, kStateType);
  }

  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("state", "the FSM state"),
             BT::InputPort<std::string>("action", "the state's action (empty = none)"),
             BT::InputPort<std::string>("final", "true when the state is final"),
             BT::InputPort<std::string>("exits", "events leaving the state, ';'-separated"),
             BT::InputPort<std::string>("params", "the state's parameters, name=value;...") };
  }

  const std::string& stateName() const { return state_; }
  const std::string& actionName() const { return action_; }
  bool isFinal() const { return final_; }
  const std::unordered_set<std::string>& exits() const { return exits_; }
  const Parameters& parameters() const { return params_; }

  /// Bind the user's callback (done by LebtRunner at load time; nullptr = no action).
  void bind(const ActionCallback* callback) { callback_ = callback; }

protected:
  BT::NodeStatus onStart() override
  {
    detail::enterState(*context_, state_, action_, params_, callback_);
    context_->event.clear();
    return final_ ? BT::NodeStatus::SUCCESS : BT::NodeStatus::RUNNING;
  }

  BT::NodeStatus onRunning() override
  {
    ++context_->leaf_ticks;
    if(!context_->event.empty())
    {
      if(exits_.count(context_->event) != 0)
      {
        return BT::NodeStatus::SUCCESS;
      }
      context_->event.clear();
    }
    return BT::NodeStatus::RUNNING;
  }

  void onHalted() override {}

private:
  Context* context_;
  std::string state_;
  std::string action_;
  bool final_ = false;
  std::unordered_set<std::string> exits_;
  Parameters params_;
  const ActionCallback* callback_ = nullptr;
};

// -- the dispatch form (docs/semantics.md section 12) ------------------------------------------

inline constexpr const char* kDispatchType = "DispatchEntry";
/// The blackboard entry holding the pending event of a dispatch tree.
inline constexpr const char* kEventKey = "event";
/// The dispatch form's state index digits and the letters a dispatch `Switch` compares them
/// with. A digit entry is a level's prefix and its digit number J (0 = least significant, at
/// most 4 decimal digits): `fsm_dJ` for the top machine, `fsm_d_<level>_J` for a composite
/// state's sub-machine in the hierarchical form (section 12a; `<level>` letters, digits and
/// `_`, J what follows the last `_`) - the grammar of fsmbt.semantics.dispatch_runtime.digit_key.
inline constexpr const char* kDigitPrefix = "fsm_d";
inline constexpr const char* kDigitLetters = "abcdefg";

namespace detail {

/// A digit entry: its level's prefix (`fsm_d` or `fsm_d_<level>_`) and its digit number
/// (-1: the key is no digit entry).
struct DigitKey
{
  std::string prefix;
  int number = -1;

  bool operator<(const DigitKey& other) const
  {
    return prefix != other.prefix ? prefix < other.prefix : number < other.number;
  }
  /// The blackboard key, `<prefix><number>`.
  std::string key() const { return prefix + std::to_string(number); }
};

/// The digit entry a blackboard key `fsm_dJ` / `fsm_d_<level>_J` names (or a port value
/// `{...}` when `braced`); number -1 when it is none.
inline DigitKey digitKey(std::string_view text, bool braced)
{
  if(braced)
  {
    if(text.size() < 2 || text.front() != '{' || text.back() != '}')
    {
      return {};
    }
    text = text.substr(1, text.size() - 2);
  }
  const std::string_view prefix(kDigitPrefix);
  if(text.size() <= prefix.size() || text.substr(0, prefix.size()) != prefix)
  {
    return {};
  }
  std::string_view rest = text.substr(prefix.size());
  std::size_t digits_at = 0;  // where J starts in `rest`
  if(rest.front() == '_')
  {
    const std::size_t last = rest.rfind('_');
    if(last < 2)  // `_<level>_` with a non-empty level
    {
      return {};
    }
    for(char ch : rest.substr(1, last - 1))
    {
      const bool word = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                        (ch >= '0' && ch <= '9') || ch == '_';
      if(!word)
      {
        return {};
      }
    }
    digits_at = last + 1;
  }
  const std::string_view number_text = rest.substr(digits_at);
  if(number_text.empty() || number_text.size() > 4)
  {
    return {};
  }
  int number = 0;
  for(char ch : number_text)
  {
    if(ch < '0' || ch > '9')
    {
      return {};
    }
    number = number * 10 + (ch - '0');
  }
  return { std::string(text.substr(0, prefix.size() + digits_at)), number };
}

/// True when `value` is one index digit (one of kDigitLetters).
inline bool isDigitLetter(std::string_view value)
{
  return value.size() == 1 && std::string_view(kDigitLetters).find(value[0]) != std::string::npos;
}

/// The `KEY:='literal'` assignments of a DispatchEntry's `_onSuccess` (joined by `;`, the one
/// script form docs/semantics.md section 12 models), as (digit entry, letter) pairs, in order.
/// Throws std::invalid_argument naming the first item that is no such assignment, writes a key
/// that is no index digit, or a value that is no index digit (one of a..g).
inline std::vector<std::pair<DigitKey, char>> decodeDigitWrites(std::string_view code)
{
  std::vector<std::pair<DigitKey, char>> writes;
  auto trim = [](std::string_view text) {
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    if(first == std::string_view::npos)
    {
      return std::string_view();
    }
    return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
  };
  std::size_t at = 0;
  while(at <= code.size())
  {
    const std::size_t end = std::min(code.find(';', at), code.size());
    const std::string_view item = trim(code.substr(at, end - at));
    at = end + 1;
    if(item.empty())
    {
      continue;
    }
    const std::size_t eq = item.find('=');
    if(eq == std::string_view::npos)
    {
      throw std::invalid_argument("'" + std::string(item) + "' is no KEY:='digit' assignment");
    }
    std::string_view key = trim(item.substr(0, eq));
    if(!key.empty() && key.back() == ':')
    {
      key = trim(key.substr(0, key.size() - 1));
    }
    std::string_view value = trim(item.substr(eq + 1));
    if(value.size() < 2 || value.front() != '\'' || value.back() != '\'')
    {
      throw std::invalid_argument("'" + std::string(item) +
                                  "' assigns no quoted literal (KEY:='digit')");
    }
    value = value.substr(1, value.size() - 2);
    DigitKey digit = digitKey(key, false);
    if(digit.number < 0)
    {
      throw std::invalid_argument("'" + std::string(item) + "' writes '" + std::string(key) +
                                  "', which is no state index digit (" + kDigitPrefix + "0, " +
                                  kDigitPrefix + "1, ...)");
    }
    if(!isDigitLetter(value))
    {
      throw std::invalid_argument("'" + std::string(item) + "' writes the malformed index digit '" +
                                  std::string(value) + "' (a digit is one of the letters " +
                                  kDigitLetters + ")");
    }
    writes.emplace_back(std::move(digit), value[0]);
  }
  return writes;
}

}  // namespace detail

/// `DispatchEntry`, the dispatch form's one leaf: runs the entered state's action (the user's
/// callback registered under its `action` port, called with the state's label and parameters)
/// and returns SUCCESS; BehaviorTree.CPP then runs its `_onSuccess` post-condition, which writes
/// the entered state's index digits (docs/semantics.md section 12).
class DispatchEntry : public BT::SyncActionNode
{
public:
  DispatchEntry(const std::string& name, const BT::NodeConfig& config, Context* context)
    : BT::SyncActionNode(name, config), context_(context)
  {
    state_ = detail::literalPort(config, name, kDispatchType, "state");
    action_ = detail::literalPort(config, name, kDispatchType, "action");
    params_ = detail::paramsPort(config, name, kDispatchType);
  }

  static BT::PortsList providedPorts()
  {
    return { BT::InputPort<std::string>("state", "the FSM state entered"),
             BT::InputPort<std::string>("action", "the state's action (empty = none)"),
             BT::InputPort<std::string>("params", "the state's parameters, name=value;...") };
  }

  const std::string& stateName() const { return state_; }
  const std::string& actionName() const { return action_; }
  const Parameters& parameters() const { return params_; }

  /// Bind the user's callback (done by LebtRunner at load time; nullptr = no action).
  void bind(const ActionCallback* callback) { callback_ = callback; }

protected:
  BT::NodeStatus tick() override
  {
    detail::enterState(*context_, state_, action_, params_, callback_);
    return BT::NodeStatus::SUCCESS;
  }

private:
  Context* context_;
  std::string state_;
  std::string action_;
  Parameters params_;
  const ActionCallback* callback_ = nullptr;
};

/// Register `LebtGuard`, `LebtState` and `DispatchEntry` in `factory`; their leaves share
/// `context`, which must outlive every tree the factory creates. LebtRunner calls this; call it
/// yourself to mix fsmbt's leaves with your own nodes in one factory.
inline void registerLebtNodes(BT::BehaviorTreeFactory& factory, Context& context)
{
  factory.registerNodeType<LebtGuard>(kGuardType, &context);
  factory.registerNodeType<LebtState>(kStateType, &context);
  factory.registerNodeType<DispatchEntry>(kDispatchType, &context);
}

/// What one macro step (or the start) did.
struct StepResult
{
  std::vector<std::string> actions;  ///< action names run, in order (entries only)
  bool terminated = false;           ///< the FSM reached a final state
  std::string state;                 ///< the current state after the step
};

/// Node types that never emit a wake-up signal in BehaviorTree.CPP 4.8 (checked in its
/// sources: the asynchronous controls, Repeat, Retry, Delay, Timeout, Sleep and threaded actions
/// do): for a tree made of these only, tickOnce() and tickExactlyOnce() are the same.
inline const std::unordered_set<std::string>& neverWakeUp()
{
  static const std::unordered_set<std::string> types = {
    kGuardType,  kStateType,      "Sequence",      "Fallback",     "ReactiveSequence",
    "ReactiveFallback", "SubTree", "Inverter",     "ForceSuccess", "ForceFailure",
    "AlwaysSuccess", "AlwaysFailure", kDispatchType, "Switch2", "Switch3", "Switch4",
    "Switch5", "Switch6", "KeepRunningUntilFailure", "Script"
  };
  return types;
}

/// How LebtRunner ticks the root.
enum class TickMode
{
  Auto,         ///< tickExactlyOnce() when every node is in neverWakeUp(), else tickOnce()
  Once,         ///< always tickOnce() (docs/semantics.md's macro step, literally)
  ExactlyOnce,  ///< always tickExactlyOnce()
};

/// The two forms of tree `fsmbt convert` writes for an event-driven machine; LebtRunner tells
/// them apart by their leaves.
enum class Form
{
  Lebt,      ///< LebtGuard / LebtState leaves (docs/semantics.md section 5; `--style lebt`)
  Dispatch,  ///< DispatchEntry leaves under a Switch dispatch (section 12; the default style)
};

/// The name `state()` reports before a dispatch tree entered its first state.
inline constexpr const char* kDispatchStart = "start";

/// Options of LebtRunner.
struct Options
{
  TickMode tick = TickMode::Auto;

  /// The start pseudo-state; default: the one guard source that is not a state, else
  /// "__start__" (docs/semantics.md section 5); for a dispatch tree "start".
  std::optional<std::string> start;
};

/// Loads an LEBT or a dispatch tree and runs it macro step by macro step (docs/semantics.md
/// sections 5 and 12).
class LebtRunner
{
public:
  /// Load the tree from XML text. Throws LebtError on an unknown leaf (naming it and its line),
  /// a malformed port, an action without a callback in `actions`, or annotations that disagree.
  LebtRunner(const std::string& xml_text, ActionRegistry actions, Options options = {})
    : registry_(std::make_unique<ActionRegistry>(std::move(actions)))
    , context_(std::make_unique<Context>())
    , factory_(std::make_unique<BT::BehaviorTreeFactory>())
  {
    context_->registry = registry_.get();
    registerLebtNodes(*factory_, *context_);
    try
    {
      tree_ = factory_->createTreeFromText(xml_text);
    }
    catch(const LebtError&)
    {
      throw;
    }
    catch(const std::exception& exc)
    {
      std::string text = std::string("cannot load the behavior tree: ") + exc.what();
      if(text.find("XML_ELEMENT_DEPTH_EXCEEDED") != std::string::npos)
      {
        text += " (BehaviorTree.CPP's XML parser, tinyxml2, nests at most 500 elements: an LEBT "
                "whose chain of states is longer than about 245 cannot be loaded)";
      }
      throw LebtError(text);
    }
    collectLeaves(xml_text);
    if(form_ == Form::Dispatch)
    {
      start_ = options.start ? *options.start : std::string(kDispatchStart);
      checkDispatch(xml_text);
      blackboard_ = tree_.rootBlackboard();
      context_->state = start_;
      exactly_once_ = options.tick == TickMode::ExactlyOnce ||
                      (options.tick == TickMode::Auto && never_wakes_up_);
      return;
    }
    start_ = options.start ? *options.start : inferStart();
    for(const LebtGuard* guard : guards_)
    {
      for(const auto& [source, event] : guard->pairs())
      {
        if(source == start_ && event.empty())
        {
          init_on_start_ = true;
        }
      }
    }
    checkAnnotations(xml_text);
    context_->state = start_;
    exactly_once_ = options.tick == TickMode::ExactlyOnce ||
                    (options.tick == TickMode::Auto && never_wakes_up_);
  }

  /// Load the tree from an XML file (LebtError when it cannot be read).
  static LebtRunner fromFile(const std::string& path, ActionRegistry actions,
                             Options options = {})
  {
    std::ifstream in(path, std::ios::binary);
    if(!in)
    {
      throw LebtError("cannot read the behavior tree file '" + path + "'");
    }
    std::ostringstream text;
    text << in.rdbuf();
    return LebtRunner(text.str(), std::move(actions), std::move(options));
  }

  LebtRunner(LebtRunner&&) = default;
  LebtRunner& operator=(LebtRunner&&) = default;

  /// Before any event: ticks once with no event when the FSM has no initial event (its initial
  /// state's action runs), else nothing (a dispatch tree: always the start tick, which runs
  /// nothing when the machine has an initial event). Call once after loading and after reset().
  StepResult start()
  {
    if(started_)
    {
      throw LebtError("LebtRunner::start() called twice without reset()");
    }
    started_ = true;
    context_->actions_run.clear();
    if(init_on_start_ || form_ == Form::Dispatch)
    {
      tick();  // a dispatch tree's start tick: `event` unset, the start case runs
    }
    return result();
  }

  /// One macro step for `event` (docs/semantics.md section 5; a dispatch tree: section 12).
  StepResult post(const std::string& event)
  {
    if(!started_)
    {
      throw LebtError("LebtRunner::post() before start()");
    }
    if(event.empty())
    {
      throw LebtError("LebtRunner::post(): an event name cannot be empty");
    }
    context_->actions_run.clear();
    if(form_ == Form::Dispatch)
    {
      // docs/semantics.md section 12: write `event`, tick once. The entry then keeps the event
      // until the next post() overwrites it; nothing ticks in between, so that is the same as
      // unsetting it (reset() does unset it), without re-creating the entry every step.
      blackboard_->set(kEventKey, event);
      tick();
      return result();
    }
    context_->event = event;
    BT::NodeStatus status = tick();
    if(status == BT::NodeStatus::SUCCESS && !context_->event.empty())
    {
      tick();
    }
    context_->event.clear();
    return result();
  }

  /// Back to before start(): the tree is halted, `state` is the start pseudo-state again.
  void reset()
  {
    tree_.haltTree();
    if(form_ == Form::Dispatch)
    {
      for(const std::string& key : blackboardKeys())
      {
        blackboard_->unset(key);
      }
    }
    context_->state = start_;
    context_->event.clear();
    context_->actions_run.clear();
    last_ = BT::NodeStatus::IDLE;
    started_ = false;
  }

  /// Root SUCCESS and the start pseudo-state left: the FSM is in a final state (a dispatch
  /// tree: root SUCCESS, docs/semantics.md section 12).
  bool terminated() const
  {
    return last_ == BT::NodeStatus::SUCCESS &&
           (form_ == Form::Dispatch || context_->state != start_);
  }

  /// Which form the loaded tree is.
  Form form() const { return form_; }

  const std::string& state() const { return context_->state; }
  const std::string& startState() const { return start_; }
  /// True when the root is ticked with tickExactlyOnce() (see TickMode).
  bool ticksExactlyOnce() const { return exactly_once_; }
  /// The status of the last root tick (IDLE before any).
  BT::NodeStatus lastRootStatus() const { return last_; }
  BT::Tree& tree() { return tree_; }
  /// LEBT leaf ticks since loading (guards and states; a cost counter for benchmarks).
  std::uint64_t leafTicks() const { return context_->leaf_ticks; }

  /// Every LebtGuard / LebtState of the tree (SubTree instances included).
  const std::vector<const LebtGuard*>& guards() const { return guards_; }
  const std::vector<const LebtState*>& states() const { return state_leaves_; }
  /// Every DispatchEntry of a dispatch tree.
  const std::vector<const DispatchEntry*>& entries() const { return entries_; }

  /// The distinct non-empty action names the tree's states run.
  std::vector<std::string> actionNames() const
  {
    std::set<std::string> names;
    for(const LebtState* leaf : state_leaves_)
    {
      if(!leaf->actionName().empty())
      {
        names.insert(leaf->actionName());
      }
    }
    for(const DispatchEntry* leaf : entries_)
    {
      if(!leaf->actionName().empty())
      {
        names.insert(leaf->actionName());
      }
    }
    return { names.begin(), names.end() };
  }

private:
  BT::NodeStatus tick()
  {
    last_ = exactly_once_ ? tree_.tickExactlyOnce() : tree_.tickOnce();
    return last_;
  }

  StepResult result() const
  {
    return StepResult{ context_->actions_run, terminated(), context_->state };
  }

  /// 1-based line of the element `<tag ...>` in `text` (0 when not found): the first one whose
  /// attributes hold name="`name`", else the first `<tag` at all.
  static int lineOf(const std::string& text, const std::string& tag, const std::string& name)
  {
    const std::string open = "<" + tag;
    const std::string named = "name=\"" + name + "\"";
    std::size_t first = std::string::npos;
    for(std::size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1))
    {
      const std::size_t after = at + open.size();
      if(after < text.size() && std::string(" \t\r\n/>").find(text[after]) == std::string::npos)
      {
        continue;  // a longer tag name (<SleepLong> for <Sleep>)
      }
      if(first == std::string::npos)
      {
        first = at;
      }
      const std::size_t end = text.find('>', after);
      if(text.substr(after, end == std::string::npos ? std::string::npos : end - after)
             .find(named) != std::string::npos)
      {
        first = at;
        break;
      }
    }
    if(first == std::string::npos)
    {
      return 0;
    }
    return 1 + static_cast<int>(std::count(text.begin(),
                                           text.begin() + static_cast<std::ptrdiff_t>(first), '\n'));
  }

  /// 1-based line of the `occurrence`-th (from 0) element `<tag ...>` of `text` whose attributes
  /// hold name="`name`" (a dispatch tree names every transition into a state by the state, so
  /// several leaves share a name); lineOf's answer when there are fewer.
  static int lineOfNth(const std::string& text, const std::string& tag, const std::string& name,
                       int occurrence)
  {
    const std::string open = "<" + tag;
    const std::string named = "name=\"" + name + "\"";
    int seen = 0;
    for(std::size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1))
    {
      const std::size_t after = at + open.size();
      if(after < text.size() && std::string(" \t\r\n/>").find(text[after]) == std::string::npos)
      {
        continue;
      }
      const std::size_t end = text.find('>', after);
      if(text.substr(after, end == std::string::npos ? std::string::npos : end - after)
             .find(named) == std::string::npos)
      {
        continue;
      }
      if(seen++ == occurrence)
      {
        return 1 + static_cast<int>(std::count(
                       text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
      }
    }
    return lineOf(text, tag, name);
  }

  /// `<Type name="..."> (path, line N)`: a node as load errors name it.
  std::string where(const BT::TreeNode* node, const std::string& xml_text) const
  {
    auto it = occurrence_.find(node);
    const std::string& type = node->registrationName();
    const int line = lineOfNth(xml_text, type, node->name(), it == occurrence_.end() ? 0 : it->second);
    return "<" + type + " name=\"" + node->name() + "\"> (" + node->fullPath() +
           (line > 0 ? ", line " + std::to_string(line) : "") + ")";
  }

  void collectLeaves(const std::string& xml_text)
  {
    std::map<std::string, std::vector<std::string>> missing;  // action -> states
    std::map<std::pair<std::string, std::string>, int> occurrences;  // (type, name) -> count
    auto need = [&](const std::string& action, const std::string& state) {
      const ActionCallback* callback = registry_->find(action);
      std::vector<std::string>& states = missing[action];
      if(callback == nullptr && std::find(states.begin(), states.end(), state) == states.end())
      {
        states.push_back(state);  // once per state: a dispatch tree enters one from many places
      }
      return callback;
    };
    for(const auto& subtree : tree_.subtrees)
    {
      for(const BT::TreeNode::Ptr& node : subtree->nodes)
      {
        const BT::NodeType type = node->type();
        const std::string& id = node->registrationName();
        occurrence_[node.get()] = occurrences[{ id, node->name() }]++;
        never_wakes_up_ = never_wakes_up_ && neverWakeUp().count(id) != 0;
        if((type == BT::NodeType::ACTION || type == BT::NodeType::CONDITION) &&
           id != kGuardType && id != kStateType && id != kDispatchType &&
           id != "AlwaysSuccess" && id != "AlwaysFailure")
        {
          const int line = lineOf(xml_text, id, node->name());
          throw LebtError("leaf <" + id + " name=\"" + node->name() + "\"> (" +
                          node->fullPath() + (line > 0 ? ", line " + std::to_string(line) : "") +
                          ") is not an LEBT leaf: this runtime runs LebtGuard and LebtState "
                          "leaves (an LEBT) or DispatchEntry leaves (the dispatch form)");
        }
        if(auto* guard = dynamic_cast<LebtGuard*>(node.get()))
        {
          guards_.push_back(guard);
        }
        else if(auto* leaf = dynamic_cast<LebtState*>(node.get()))
        {
          state_leaves_.push_back(leaf);
          if(!leaf->actionName().empty())
          {
            leaf->bind(need(leaf->actionName(), leaf->stateName()));
          }
        }
        else if(auto* entry = dynamic_cast<DispatchEntry*>(node.get()))
        {
          entries_.push_back(entry);
          if(!entry->actionName().empty())
          {
            entry->bind(need(entry->actionName(), entry->stateName()));
          }
        }
      }
    }
    if(!entries_.empty())
    {
      if(!guards_.empty() || !state_leaves_.empty())
      {
        const BT::TreeNode* lebt = guards_.empty() ?
                                       static_cast<const BT::TreeNode*>(state_leaves_.front()) :
                                       static_cast<const BT::TreeNode*>(guards_.front());
        throw LebtError(where(lebt, xml_text) + " and " + where(entries_.front(), xml_text) +
                        ": a tree is an LEBT (LebtGuard/LebtState) or the dispatch form "
                        "(DispatchEntry), not both");
      }
      form_ = Form::Dispatch;
    }
    for(auto it = missing.begin(); it != missing.end();)
    {
      it = it->second.empty() ? missing.erase(it) : std::next(it);
    }
    if(!missing.empty())
    {
      std::string text = "no callback registered for action(s): ";
      bool first = true;
      for(const auto& [action, states] : missing)
      {
        text += (first ? "'" : ", '") + action + "' (state " + states.front() +
                (states.size() > 1 ? " and " + std::to_string(states.size() - 1) + " more" : "") +
                ")";
        first = false;
      }
      throw LebtError(text + "; register each with ActionRegistry::add (or addFallback)");
    }
    if(state_leaves_.empty() && entries_.empty())
    {
      throw LebtError("the tree has no LebtState or DispatchEntry leaf: it is not a tree "
                      "`fsmbt convert` wrote from a state machine");
    }
  }

  /// The children of `node` (a control's, a decorator's or SubTree's one; none for a leaf).
  static std::vector<const BT::TreeNode*> childrenOf(const BT::TreeNode* node)
  {
    if(const auto* control = dynamic_cast<const BT::ControlNode*>(node))
    {
      return { control->children().begin(), control->children().end() };
    }
    if(const auto* decorator = dynamic_cast<const BT::DecoratorNode*>(node))
    {
      if(decorator->child() != nullptr)
      {
        return { decorator->child() };
      }
    }
    return {};
  }

  /// A `Switch` on an index digit `{fsm_dJ}` / `{fsm_d_<level>_J}`: its digit entry and its
  /// case letters, in order.
  struct IndexSwitch
  {
    detail::DigitKey digit;
    std::string cases;
  };

  /// The dispatch tree's annotations agree (docs/semantics.md section 12, "Checked at load
  /// time"; the flat form and the hierarchical form of section 12a), checked on the loaded tree,
  /// never at tick time; a LebtError names the first node that disagrees, with its line. The
  /// rule of fsmbt.semantics.dispatch_check, the Python runtime's:
  ///  - only a DispatchEntry carries a post-condition, `_onSuccess` alone, made of
  ///    `KEY:='x'` assignments of index digits x in a..g to digit entries (`fsm_dJ`, or
  ///    `fsm_d_<level>_J` for a composite's level) that the Switches read (J below the digits
  ///    they read of that level); no node carries a pre-condition (either could change the
  ///    index unseen);
  ///  - at least one Switch reads a digit entry, and each of its cases is one index digit;
  ///  - the index is the joint valuation of every level's digits; it resolves from the root:
  ///    an index Switch takes its digit's case (the default when none equals it), a SubTree
  ///    its tree, a control node that is no Switch and whose first child is (through SubTrees)
  ///    an index Switch - a composite's ReactiveFallback - its first child, its other children
  ///    holding that composite's own transitions. The node reached is the state's case, and the
  ///    state's transitions are the DispatchEntry leaves in it and in the own transitions
  ///    passed;
  ///  - every index a transition writes is a state's: from the start (no digit set), each
  ///    DispatchEntry of a reached state writes an index (the state's with its `_onSuccess`
  ///    applied) that must set every digit and lead to a state's case, neither back to the
  ///    start case nor to an `AlwaysFailure` (a padding case or an unused default) - except,
  ///    inside a composite (below a Switch on a `fsm_d_<level>_` digit), an `AlwaysFailure`
  ///    named as the state the leaf enters (a final sub-state, or one whose events only its
  ///    ancestors handle); and every leaf writing one index names the same `state`.
  /// Cost: O(nodes + reachable configurations x (digits + nesting) + transitions x digits).
  void checkDispatch(const std::string& xml_text)
  {
    std::unordered_map<const BT::TreeNode*, IndexSwitch> switches;
    std::unordered_map<const DispatchEntry*, std::vector<std::pair<detail::DigitKey, char>>> writes;
    std::map<std::string, int> widths;  // level prefix -> digits its Switches read
    for(const auto& subtree : tree_.subtrees)
    {
      for(const BT::TreeNode::Ptr& node : subtree->nodes)
      {
        const BT::NodeConfig& config = std::as_const(*node).config();
        const auto* entry = dynamic_cast<const DispatchEntry*>(node.get());
        if(!config.pre_conditions.empty())
        {
          throw LebtError(where(node.get(), xml_text) + ": a pre-condition (_skipIf, " +
                          "_successIf, ...) in a dispatch tree is not modelled: it could " +
                          "change the state index unseen");
        }
        for(const auto& [kind, code] : config.post_conditions)
        {
          if(entry == nullptr || kind != BT::PostCond::ON_SUCCESS)
          {
            throw LebtError(where(node.get(), xml_text) + ": in a dispatch tree only a " +
                            "DispatchEntry carries a post-condition, _onSuccess");
          }
          try
          {
            writes[entry] = detail::decodeDigitWrites(code);
          }
          catch(const std::invalid_argument& exc)
          {
            throw LebtError(where(node.get(), xml_text) +
                            ": dispatch annotations disagree: _onSuccess " + exc.what());
          }
        }
        if(!isSwitch(node.get()))
        {
          continue;
        }
        auto variable = config.input_ports.find("variable");
        detail::DigitKey digit = variable == config.input_ports.end() ?
                                     detail::DigitKey{} :
                                     detail::digitKey(variable->second, true);
        if(digit.number < 0)
        {
          continue;  // a Switch on {event}
        }
        IndexSwitch info{ digit, {} };
        const std::size_t cases = childrenOf(node.get()).size() - 1;
        for(std::size_t k = 1; k <= cases; ++k)
        {
          auto value = config.input_ports.find("case_" + std::to_string(k));
          const std::string text = value == config.input_ports.end() ? "" : value->second;
          if(!detail::isDigitLetter(text))
          {
            throw LebtError(where(node.get(), xml_text) +
                            ": dispatch annotations disagree: case_" + std::to_string(k) +
                            " is the malformed index digit '" + text +
                            "' (a digit is one of the letters " + kDigitLetters + ")");
          }
          info.cases.push_back(text[0]);
        }
        int& width = widths[digit.prefix];
        width = std::max(width, digit.number + 1);
        switches.emplace(node.get(), std::move(info));
      }
    }
    if(switches.empty())
    {
      throw LebtError(where(entries_.front(), xml_text) + ": dispatch annotations disagree: no " +
                      "Switch reads a state index digit ({" + kDigitPrefix + "0}, ...): a tree " +
                      "of DispatchEntry leaves is the dispatch form, a Switch dispatch over the " +
                      "index");
    }
    // the joint index: one slot per digit, the top level's (`fsm_d`, the smallest prefix) first,
    // then each composite level's by prefix, each least significant digit first
    std::vector<detail::DigitKey> keys;
    std::map<detail::DigitKey, std::size_t> slot;
    for(const auto& [prefix, width] : widths)
    {
      for(int j = 0; j < width; ++j)
      {
        slot.emplace(detail::DigitKey{ prefix, j }, keys.size());
        keys.push_back(detail::DigitKey{ prefix, j });
      }
    }
    std::unordered_map<const DispatchEntry*, std::vector<std::pair<std::size_t, char>>> slots;
    for(const auto& [entry, items] : writes)
    {
      for(const auto& [digit, letter] : items)
      {
        auto width = widths.find(digit.prefix);
        const int has = width == widths.end() ? 0 : width->second;
        if(digit.number >= has)
        {
          const std::string why =
              digit.prefix == kDigitPrefix ? "the index has " + std::to_string(has) :
              has > 0 ? "the level " + digit.prefix + ".. has " + std::to_string(has) :
                        "no Switch reads a digit of the level " + digit.prefix + "..";
          throw LebtError(where(entry, xml_text) + ": dispatch annotations disagree: " +
                          "_onSuccess writes " + digit.key() + ", but no Switch reads that " +
                          "digit (" + why + ")");
        }
        slots[entry].emplace_back(slot.at(digit), letter);
      }
    }
    auto isIndex = [&](const BT::TreeNode* node) {
      while(switches.count(node) == 0 && node->registrationName() == "SubTree")
      {
        const std::vector<const BT::TreeNode*> children = childrenOf(node);
        if(children.empty())
        {
          return false;
        }
        node = children.front();
      }
      return switches.count(node) > 0;
    };
    struct Resolved
    {
      const BT::TreeNode* node = nullptr;     // the state's case
      std::vector<const BT::TreeNode*> own;  // own transitions passed
      bool inside = false;                     // below a composite level's Switch
    };
    // where the index Switches lead `index` (index[slot] = that digit's letter, 0 = unset)
    auto resolve = [&](const std::string& index) {
      Resolved out;
      const BT::TreeNode* node = tree_.rootNode();
      for(;;)
      {
        auto it = switches.find(node);
        const std::vector<const BT::TreeNode*> children = childrenOf(node);
        if(it != switches.end())
        {
          const char value = index[slot.at(it->second.digit)];
          const std::size_t at = it->second.cases.find(value);
          out.inside = out.inside || it->second.digit.prefix != kDigitPrefix;
          node = children[at == std::string::npos || value == 0 ? children.size() - 1 : at];
        }
        else if(node->registrationName() == "SubTree" && !children.empty())
        {
          node = children.front();
        }
        else if(dynamic_cast<const BT::ControlNode*>(node) != nullptr && !isSwitch(node) &&
                children.size() > 1 && isIndex(children.front()))
        {
          out.own.insert(out.own.end(), children.begin() + 1, children.end());
          node = children.front();
        }
        else
        {
          out.node = node;
          return out;
        }
      }
    };
    auto shown = [&](const std::string& index) {  // most significant digit first
      std::vector<std::pair<std::string, std::string>> parts;  // (prefix, digits)
      for(std::size_t k = 0; k < keys.size(); ++k)
      {
        if(parts.empty() || parts.back().first != keys[k].prefix)
        {
          parts.emplace_back(keys[k].prefix, "");
        }
        parts.back().second.insert(parts.back().second.begin(), index[k] == 0 ? '-' : index[k]);
      }
      if(parts.size() == 1 && parts.front().first == kDigitPrefix)
      {
        return "'" + parts.front().second + "'";
      }
      std::string text;
      for(const auto& [prefix, digits] : parts)
      {
        text += (text.empty() ? "" : ", ") + prefix + "='" + digits + "'";
      }
      return text;
    };
    const std::string start(keys.size(), '\0');
    const BT::TreeNode* start_case = resolve(start).node;
    std::unordered_map<std::string, const DispatchEntry*> named;  // index -> first entry
    std::vector<std::pair<std::string, std::vector<const BT::TreeNode*>>> queue{
      { start, { start_case } }
    };
    for(std::size_t next = 0; next < queue.size(); ++next)
    {
      const std::string source = queue[next].first;
      std::vector<const BT::TreeNode*> stack(queue[next].second.rbegin(),
                                             queue[next].second.rend());
      while(!stack.empty())
      {
        const BT::TreeNode* node = stack.back();
        stack.pop_back();
        const std::vector<const BT::TreeNode*> children = childrenOf(node);
        stack.insert(stack.end(), children.rbegin(), children.rend());
        const auto* entry = dynamic_cast<const DispatchEntry*>(node);
        if(entry == nullptr)
        {
          continue;
        }
        std::string target = source;
        auto written = slots.find(entry);
        if(written != slots.end())
        {
          for(const auto& [at, letter] : written->second)
          {
            target[at] = letter;
          }
        }
        const std::size_t unset = target.find('\0');
        if(unset != std::string::npos)
        {
          throw LebtError(where(entry, xml_text) + ": dispatch annotations disagree: entering '" +
                          entry->stateName() + "' from the start, _onSuccess leaves " +
                          keys[unset].key() +
                          " unset (from the start every index digit is written)");
        }
        auto first = named.find(target);
        if(first != named.end())
        {
          if(first->second->stateName() != entry->stateName())
          {
            throw LebtError(where(entry, xml_text) + ": dispatch annotations disagree: it " +
                            "enters '" + entry->stateName() + "' but writes the state index " +
                            shown(target) + " of '" + first->second->stateName() + "' (" +
                            where(first->second, xml_text) + ")");
          }
          continue;
        }
        Resolved found = resolve(target);
        const bool failure = found.node->registrationName() == "AlwaysFailure";
        const bool final_inside =
            failure && found.inside && found.node->name() == entry->stateName();
        if(found.node == start_case || (failure && !final_inside))
        {
          throw LebtError(where(entry, xml_text) + ": dispatch annotations disagree: entering '" +
                          entry->stateName() + "', _onSuccess writes the state index " +
                          shown(target) + ", which no state has (the index Switches lead it to " +
                          (found.node == start_case ? std::string("the start case") :
                                                      where(found.node, xml_text)) +
                          ")");
        }
        named.emplace(target, entry);
        found.own.insert(found.own.begin(), found.node);
        queue.emplace_back(target, std::move(found.own));
      }
    }
  }

  /// True when `node` is one of BehaviorTree.CPP's `Switch2`..`Switch6`.
  static bool isSwitch(const BT::TreeNode* node)
  {
    return node->registrationName().rfind("Switch", 0) == 0;
  }

  /// The blackboard entries a dispatch tree's run writes (the index digits and `event`).
  std::vector<std::string> blackboardKeys() const
  {
    std::vector<std::string> keys;
    for(const auto& key : blackboard_->getKeys())
    {
      const std::string text(key);
      if(text == kEventKey || detail::digitKey(text, false).number >= 0)
      {
        keys.push_back(text);
      }
    }
    return keys;
  }

  /// The LEBT annotations agree (docs/semantics.md section 5): every guard pair leaving a
  /// state names one of its exits, every exit is taken by some pair, and every pair source that
  /// is no state is the start pseudo-state. Throws LebtError naming the first leaf that does
  /// not, with its line.
  void checkAnnotations(const std::string& xml_text) const
  {
    std::unordered_map<std::string, const LebtState*> states;
    for(const LebtState* leaf : state_leaves_)
    {
      states.emplace(leaf->stateName(), leaf);
    }
    auto where = [&](const BT::TreeNode* node, const char* type) {
      const int line = lineOf(xml_text, type, node->name());
      return std::string("<") + type + " name=\"" + node->name() + "\"> (" + node->fullPath() +
             (line > 0 ? ", line " + std::to_string(line) : "") + ")";
    };
    std::set<std::pair<std::string, std::string>> taken;
    for(const LebtGuard* guard : guards_)
    {
      for(const auto& [source, event] : guard->pairs())
      {
        taken.emplace(source, event);
        auto state = states.find(source);
        if(state == states.end())
        {
          if(source != start_)
          {
            throw LebtError(where(guard, kGuardType) + ": LEBT annotations disagree: pair '" +
                            source + "/" + event + "': '" + source +
                            "' is no state of the tree and not the start pseudo-state '" +
                            start_ + "', so the transition never fires");
          }
        }
        else if(!event.empty() && state->second->exits().count(event) == 0)
        {
          throw LebtError(where(guard, kGuardType) + ": LEBT annotations disagree: pair '" +
                          source + "/" + event + "': state '" + source + "' does not list '" +
                          event + "' in its exits port, so this transition never fires");
        }
      }
    }
    for(const LebtState* leaf : state_leaves_)
    {
      for(const std::string& exit : leaf->exits())
      {
        if(taken.count({ leaf->stateName(), exit }) == 0)
        {
          throw LebtError(where(leaf, kStateType) + ": LEBT annotations disagree: exits port " +
                          "lists '" + exit + "' but no LebtGuard has the pair '" +
                          leaf->stateName() + "/" + exit + "'");
        }
      }
    }
  }

  std::string inferStart() const
  {
    std::unordered_set<std::string> names;
    for(const LebtState* leaf : state_leaves_)
    {
      names.insert(leaf->stateName());
    }
    std::set<std::string> sources;
    for(const LebtGuard* guard : guards_)
    {
      for(const auto& pair : guard->pairs())
      {
        if(names.count(pair.first) == 0)
        {
          sources.insert(pair.first);
        }
      }
    }
    if(sources.size() > 1)
    {
      // a misspelt state among them: the start is the source of the initialisation pair
      std::set<std::string> initial;
      for(const LebtGuard* guard : guards_)
      {
        for(const auto& pair : guard->pairs())
        {
          if(pair.second.empty() && sources.count(pair.first) != 0)
          {
            initial.insert(pair.first);
          }
        }
      }
      if(initial.size() == 1)
      {
        return *initial.begin();
      }
    }
    return sources.size() == 1 ? *sources.begin() : std::string(kDefaultStart);
  }

  std::unique_ptr<ActionRegistry> registry_;
  std::unique_ptr<Context> context_;
  std::unique_ptr<BT::BehaviorTreeFactory> factory_;
  BT::Tree tree_;
  std::vector<const LebtGuard*> guards_;
  std::vector<const LebtState*> state_leaves_;
  std::vector<const DispatchEntry*> entries_;
  std::unordered_map<const BT::TreeNode*, int> occurrence_;  // n-th node of its (type, name)
  BT::Blackboard::Ptr blackboard_;                            // a dispatch tree's
  Form form_ = Form::Lebt;
  std::string start_;
  bool init_on_start_ = false;
  bool never_wakes_up_ = true;
  bool exactly_once_ = false;
  bool started_ = false;
  BT::NodeStatus last_ = BT::NodeStatus::IDLE;
};

}  // namespace lebt
}  // namespace fsmbt
