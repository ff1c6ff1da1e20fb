"""A small hand-written LEBT with state parameters, and the hand edits that break it.

Three states run by two actions: A and B are both ``TimedCmdVelState`` (one action, two
velocities: the runtimes' callbacks must tell them apart by label and parameters), C is a final
``LogState``. ``BROKEN`` lists edits a person makes by hand, each with a piece of the load error
both runtimes must give (naming the node), never a silent stop at tick time.
"""

from __future__ import annotations

TREE = """<root BTCPP_format="4" main_tree_to_execute="MainTree">
  <BehaviorTree ID="MainTree">
    <Sequence name="LEBT">
      <Fallback name="A_selector">
        <LebtGuard name="Enter_A" target="A" pairs="__start__/"/>
        <Sequence name="A_chain">
          <LebtState name="A" state="A" action="TimedCmdVelState" final="false" exits="go" params="velocity=0.5;duration=2"/>
          <Fallback name="B_selector">
            <LebtGuard name="Enter_B" target="B" pairs="A/go"/>
            <Sequence name="B_chain">
              <LebtState name="B" state="B" action="TimedCmdVelState" final="false" exits="stop" params="velocity=-0.2;duration=1"/>
              <Fallback name="C_selector">
                <LebtGuard name="Enter_C" target="C" pairs="B/stop"/>
                <LebtState name="C" state="C" action="LogState" final="true" exits="" params="text=done\\;bye"/>
              </Fallback>
            </Sequence>
          </Fallback>
        </Sequence>
      </Fallback>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Condition ID="LebtGuard">
      <input_port name="target"/><input_port name="pairs"/>
    </Condition>
    <Action ID="LebtState">
      <input_port name="state"/><input_port name="action"/><input_port name="final"/>
      <input_port name="exits"/><input_port name="params"/>
    </Action>
  </TreeNodesModel>
</root>
"""

#: The entries the tree makes on start, "go", "stop": (action, state, params).
ENTRIES = [
    ("TimedCmdVelState", "A", {"velocity": "0.5", "duration": "2"}),
    ("TimedCmdVelState", "B", {"velocity": "-0.2", "duration": "1"}),
    ("LogState", "C", {"text": "done;bye"}),
]

#: (name, replaced text, replacement, piece of the error, line of the named node)
BROKEN = [
    ("pair event not an exit", 'pairs="A/go"', 'pairs="A/og"', "Enter_B", 9),
    ("pair source no state", 'pairs="B/stop"', 'pairs="B/stop;Bx/stop"', "Enter_C", 13),
    ("exit without a guard", 'exits="stop"', 'exits="stop;halt"', "B", 11),
    ("malformed params", 'params="velocity=0.5;duration=2"', 'params="velocity"', "A", 7),
]


def broken(replaced: str, replacement: str) -> str:
    assert replaced in TREE
    return TREE.replace(replaced, replacement, 1)
