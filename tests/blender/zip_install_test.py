"""The packaged add-on (scripts/package-blender-addon.sh) installed the way a user installs it:
Preferences > Add-ons > Install of the zip into an empty user scripts folder
($BLENDER_USER_SCRIPTS, set by scripts/blender-test.sh), then F12 of the default cube against
the server at $PENUMBRA_URL. Checks that the zip is self-contained: the client it uses is the
copy inside it, not the repository's. Arguments after `--`: the zip."""
import os
import sys

import bpy


def main(zip_path):
    bpy.ops.preferences.addon_install(filepath=zip_path)
    bpy.ops.preferences.addon_enable(module="penumbra_blender")
    import penumbra_blender
    from penumbra_blender.client_import import load_client
    client = load_client()
    installed = os.path.dirname(penumbra_blender.__file__)
    assert client.__name__ == "penumbra_blender.penumbra", client.__name__
    assert os.path.dirname(client.__file__).startswith(installed), client.__file__
    assert installed.startswith(os.environ["BLENDER_USER_SCRIPTS"]), installed
    scene = bpy.context.scene
    scene.render.engine = "PENUMBRA"
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    scene.penumbra.samples = 2
    bpy.ops.render.render()
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR"
    settings.color_depth = "32"
    out = os.path.join(os.environ["BLENDER_USER_SCRIPTS"], "zip.exr")
    bpy.data.images["Render Result"].save_render(out, scene=scene)
    image = bpy.data.images.load(out)
    brightest = max(image.pixels[:])
    assert brightest > 0.01, brightest
    print(f"zip install: OK (client {client.__file__}, brightest {brightest:.3f})")


if __name__ == "__main__":
    try:
        main(sys.argv[sys.argv.index("--") + 1])
    except Exception as e:  # noqa: BLE001 - any failure is the test's failure
        import traceback
        traceback.print_exc()
        sys.exit(1)
