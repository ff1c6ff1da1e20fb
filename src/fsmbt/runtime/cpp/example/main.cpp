// Minimal program running a tree written by `fsmbt convert` from a state machine (here: the door
// of examples/door_hfsm.scxml) in BehaviorTree.CPP v4 with the user's own actions: the dispatch
// form (the default) or an LEBT (--style lebt); LebtRunner tells them apart.
//
//   lebt_example TREE.xml EVENT...
//
// Each state's action calls the function registered under the action's name, once per entry of
// the state. Loading fails (exit 1, one line) when the tree uses a leaf other than fsmbt's
// (LebtGuard / LebtState, or DispatchEntry), names an action that has no registered function,
// or carries annotations a hand edit broke.
#include <fsmbt/lebt.hpp>

#include <iostream>

int main(int argc, char** argv)
{
  if(argc < 2)
  {
    std::cerr << "usage: " << argv[0] << " TREE.xml EVENT...\n";
    return 2;
  }
  fsmbt::lebt::ActionRegistry actions;
  for(const char* name : { "Closed", "Opening", "Open", "Closing", "Emergency", "Off" })
  {
    // In a ROS 2 node these would send goals, publish, etc.
    actions.add(name, [name](const std::string& state) {
      std::cout << "  action " << name << " (entered " << state << ")\n";
    });
  }
  try
  {
    fsmbt::lebt::LebtRunner runner = fsmbt::lebt::LebtRunner::fromFile(argv[1], actions);
    runner.start();
    std::cout << "start: state " << runner.state() << "\n";
    for(int i = 2; i < argc; ++i)
    {
      const fsmbt::lebt::StepResult step = runner.post(argv[i]);
      std::cout << "event " << argv[i] << ": state " << step.state
                << (step.actions.empty() ? " (ignored)" : "")
                << (step.terminated ? ", terminated" : "") << "\n";
    }
  }
  catch(const fsmbt::lebt::LebtError& error)
  {
    std::cerr << "error: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
