// fsmbt_btcpp_xsd: print the XSD BehaviorTree.CPP itself generates (BT::writeTreeXSD) for its
// built-in nodes plus the nodes declared on standard input.
//
// Why: fsmbt checks every BT file it writes against the schema BehaviorTree.CPP 4.8.2 says a
// valid file has (docs/formats/btcpp.md "Checked against BehaviorTree.CPP's XSD"). The Python
// side (fsmbt.runtime.btcpp_xsd) sends the written file's <TreeNodesModel>, one node a line:
//     KIND ID [DIRECTION:PORT ...]
// KIND is Action, Condition, Control or Decorator; DIRECTION is input, output or inout. Only the
// manifests matter to writeTreeXSD: the builders of declared nodes are never called.
#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/xml_parsing.h>

#include <iostream>
#include <sstream>
#include <string>

namespace
{
BT::NodeType kindOf(const std::string& kind)
{
  if(kind == "Action")
    return BT::NodeType::ACTION;
  if(kind == "Condition")
    return BT::NodeType::CONDITION;
  if(kind == "Control")
    return BT::NodeType::CONTROL;
  if(kind == "Decorator")
    return BT::NodeType::DECORATOR;
  throw std::runtime_error("unknown node kind: " + kind);
}
}  // namespace

int main(int argc, char** argv)
{
  if(argc == 2 && std::string(argv[1]) == "--version")
  {
    std::cout << "fsmbt-btcpp-xsd 1.0 on BehaviorTree.CPP " << BT::LibraryVersionString()
              << "\n";
    return 0;
  }
  try
  {
    BT::BehaviorTreeFactory factory;
    std::string line;
    while(std::getline(std::cin, line))
    {
      std::istringstream words(line);
      std::string kind, id, port;
      if(!(words >> kind >> id))
        continue;
      BT::TreeNodeManifest manifest;
      manifest.type = kindOf(kind);
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
      // a declaration under a built-in's name (hans-ros-supervisor's v3 Sleep action):
      // BehaviorTree.CPP 4.8.2 cannot register it (a built-in cannot be removed), so the
      // built-in's own schema stays, said on stderr
      if(factory.builtinNodes().count(id) != 0)
      {
        std::cerr << "fsmbt_btcpp_xsd: " << id << " is a built-in; its declaration is not used\n";
        continue;
      }
      factory.registerBuilder(manifest, [](const std::string&, const BT::NodeConfig&)
                              -> std::unique_ptr<BT::TreeNode> { return nullptr; });
    }
    std::cout << BT::writeTreeXSD(factory);
    return 0;
  }
  catch(const std::exception& error)
  {
    std::cerr << "fsmbt_btcpp_xsd: " << error.what() << "\n";
    return 2;
  }
}
