"""Alternative solutions of In-between and Fill gap, to cycle through.

With "Alternatives" above 0, In-between and Fill gap ask the library for
more solutions from other starts (motionfield.solve); the first is keyed as
usual and all of them are kept here, in memory, for the action they were
made for. "Next" and "Previous" key another one on the same generated frames.
Which one is keyed is a property of the action, so undo brings the number
back with the keys. The solutions are forgotten when the animator's keys
change (a regenerate makes new ones) or the file is reloaded.
"""

from . import animation

INDEX_PROP = "motionfield_alternative"  # the action's keyed alternative (0 = the method's answer)

_kept = {}  # action name -> _Choice


class _Choice:
    def __init__(self, obj, rig, sampled, new, keyed, motions):
        self.rig = rig
        self.sampled = sampled
        self.new = set(new)
        self.keyed = sorted(keyed)
        self.range = (sampled.frames[0], sampled.frames[-1])
        self.poses = [(m.rotations, m.root_positions) for m in motions]
        self.keys = animation.animator_keys(obj, rig.names, *self.range)  # what the solutions were made from


def remember(obj, rig, sampled, new, keyed, motions):
    """Keeps `motions` (the method's answer first) for the armature's action,
    keyed on `new`; forgets them when there is only one."""
    action = obj.animation_data.action
    if len(motions) > 1:
        _kept[action.name] = _Choice(obj, rig, sampled, new, keyed, motions)
    else:
        _kept.pop(action.name, None)
    action[INDEX_PROP] = 0


def current(obj):
    """(the keyed alternative, how many) for the armature's action, or None
    when there are none or they are out of date (keys added or removed,
    generated frames cleared, another rig). A key whose value was edited is
    found by step() (comparing every key is too slow for the panel's draw)."""
    if obj is None or obj.type != 'ARMATURE' or obj.animation_data is None:
        return None
    action = obj.animation_data.action
    choice = _kept.get(action.name) if action is not None else None
    if choice is None:
        return None
    if not choice.new <= animation.generated_frames(action) or \
            animation.keyed_frames(obj, choice.rig.names) != choice.keyed or \
            any(name not in obj.pose.bones for name in choice.rig.names):
        return None
    return int(action.get(INDEX_PROP, 0)) % len(choice.poses), len(choice.poses)


def step(obj, delta):
    """Keys the alternative `delta` away (cyclically) on the generated frames;
    returns (its index, how many). ValueError when there is nothing to cycle."""
    state = current(obj)
    if state is None:
        raise ValueError("no alternatives to cycle through: run In-between or Fill gap with Alternatives above 0")
    action = obj.animation_data.action
    choice = _kept[action.name]
    if animation.animator_keys(obj, choice.rig.names, *choice.range) != choice.keys:
        del _kept[action.name]
        raise ValueError("the keys changed since the alternatives were made: run In-between or Fill gap again")
    index = (state[0] + delta) % state[1]
    rotations, root_positions = choice.poses[index]
    values = animation.channel_values(obj, choice.rig, choice.sampled, rotations, root_positions, choice.new)
    animation.insert_keys(obj, choice.rig, choice.sampled, values, choice.new, set(choice.keyed))
    action[INDEX_PROP] = index
    return index, state[1]
