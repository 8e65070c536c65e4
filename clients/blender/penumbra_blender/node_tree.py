"""Reading Blender shader node trees: what a material's or world's output is fed by."""
from __future__ import annotations


def output_shader(tree, output_type: str):
    """The node linked to the Surface input of the tree's active output node of `output_type`
    (ShaderNodeOutputMaterial, ShaderNodeOutputWorld), or None."""
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.bl_idname == output_type]
    active = [n for n in outputs if n.is_active_output] or outputs
    for node in active:
        socket = node.inputs.get("Surface")
        if socket is not None and socket.is_linked:
            return socket.links[0].from_node
    return None
