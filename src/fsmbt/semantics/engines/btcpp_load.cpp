// fsmbt_btcpp_load: does BehaviorTree.CPP itself load a tree file fsmbt wrote?
//
//   fsmbt_btcpp_load TREE.xml < DECLARATIONS
//   fsmbt_btcpp_load --version
//
// Why: `fsmbt convert` checks each behavior tree it writes by loading it in the engine it is
// for (docs/semantics.md section 5, "Every written tree loads"). The Python side
// (fsmbt.semantics.engines.btcpp_load) sends the file's <TreeNodesModel>, one node a line:
//     KIND ID [DIRECTION:PORT ...]
// KIND is Action, Condition, Control or Decorator; DIRECTION is input, output or inout. Each
// declared node is registered with exactly those ports (so an attribute the model does not
// declare is BehaviorTree.CPP's own load error) and a stand-in behaviour: an action or a
// condition returns SUCCESS, a control ticks its children in order as a Sequence does, a
// decorator returns its child's status. Then BT::BehaviorTreeFactory::createTreeFromFile is
// called: the XML is parsed by BehaviorTree.CPP's tinyxml2 (its nesting limit included), every
// tree of the file is registered, and the main tree with its SubTrees is instantiated.
//
// Output (stdout): one JSON object {"loaded":true,"nodes":N,"version":"4.8.2"}. A refusal goes
// to stderr as one line `error: ...` with exit status 1; bad arguments exit 2.
#include <behaviortree_cpp/bt_factory.h>

#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

namespace
{
class StandInAction : public BT::SyncActionNode
{
public:
  StandInAction(const std::string& name, const BT::NodeConfig& config)
    : BT::SyncActionNode(name, config)
  {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class StandInCondition : public BT::ConditionNode
{
public:
  StandInCondition(const std::string& name, const BT::NodeConfig& config)
    : BT::ConditionNode(name, config)
  {}
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

class StandInControl : public BT::ControlNode
{
public:
  StandInControl(const std::string& name, const BT::NodeConfig& config)
    : BT::ControlNode(name, config)
  {}
  BT::NodeStatus tick() override
  {
    for(BT::TreeNode* child : children_nodes_)
    {
      const BT::NodeStatus status = child->executeTick();
      if(status != BT::NodeStatus::SUCCESS)
      {
        return status;
      }
    }
    resetChildren();
    return BT::NodeStatus::SUCCESS;
  }
};

class StandInDecorator : public BT::DecoratorNode
{
public:
  StandInDecorator(const std::string& name, const BT::NodeConfig& config)
    : BT::DecoratorNode(name, config)
  {}
  BT::NodeStatus tick() override { return child_node_->executeTick(); }
};

template <typename Node>
BT::NodeBuilder builder()
{
  return [](const std::string& name, const BT::NodeConfig& config) {
    return std::make_unique<Node>(name, config);
  };
}

void declare(BT::BehaviorTreeFactory& factory, const std::string& line)
{
  std::istringstream words(line);
  std::string kind, id, port;
  if(!(words >> kind >> id))
  {
    return;
  }
  if(factory.builtinNodes().count(id) != 0)
  {
    return;  // a built-in's own manifest stays (BehaviorTree.CPP cannot replace it either)
  }
  BT::TreeNodeManifest manifest;
  manifest.registration_ID = id;
  while(words >> port)
  {
    const auto colon = port.find(':');
    const std::string direction = port.substr(0, colon);
    const std::string name = port.substr(colon + 1);
    if(direction == "output")
      manifest.ports.insert(BT::OutputPort<std::string>(name));
    else if(direction == "inout")
      manifest.ports.insert(BT::BidirectionalPort<std::string>(name));
    else
      manifest.ports.insert(BT::InputPort<std::string>(name));
  }
  if(kind == "Action")
  {
    manifest.type = BT::NodeType::ACTION;
    factory.registerBuilder(manifest, builder<StandInAction>());
  }
  else if(kind == "Condition")
  {
    manifest.type = BT::NodeType::CONDITION;
    factory.registerBuilder(manifest, builder<StandInCondition>());
  }
  else if(kind == "Control")
  {
    manifest.type = BT::NodeType::CONTROL;
    factory.registerBuilder(manifest, builder<StandInControl>());
  }
  else if(kind == "Decorator")
  {
    manifest.type = BT::NodeType::DECORATOR;
    factory.registerBuilder(manifest, builder<StandInDecorator>());
  }
  else
  {
    throw std::runtime_error("unknown node kind in the declarations: " + kind);
  }
}
}  // namespace

int main(int argc, char** argv)
{
  if(argc == 2 && std::string(argv[1]) == "--version")
  {
    std::cout << "fsmbt-btcpp-load 1.0 on BehaviorTree.CPP " << BT::LibraryVersionString()
              << "\n";
    return 0;
  }
  if(argc != 2)
  {
    std::cerr << "usage: fsmbt_btcpp_load TREE.xml < DECLARATIONS | --version\n";
    return 2;
  }
  try
  {
    BT::BehaviorTreeFactory factory;
    for(std::string line; std::getline(std::cin, line);)
    {
      declare(factory, line);
    }
    BT::Tree tree = factory.createTreeFromFile(argv[1]);
    long nodes = 0;
    tree.applyVisitor([&nodes](const BT::TreeNode*) { ++nodes; });
    std::printf("{\"loaded\":true,\"nodes\":%ld,\"version\":\"%s\"}\n", nodes,
                BT::LibraryVersionString());
    return 0;
  }
  catch(const std::exception& error)
  {
    std::string message = error.what();
    for(char& ch : message)
    {
      if(ch == '\n' || ch == '\r')
        ch = ' ';
    }
    std::fprintf(stderr, "error: %s\n", message.c_str());
    return 1;
  }
}
