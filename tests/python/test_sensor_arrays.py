"""Every sensor as an array (issue 30, part 5): vision-sensor images and depth
(compared with the program's snapshots of the same sensor), blob cameras, force
sensors, distance and collision objects."""

import pathlib
import struct
import tempfile
import unittest
import zlib

import numpy as np

import swarmsim
from common import BINARY, run, world

# A box robot with a camera looking ahead, a LED and a blob camera on top, a
# weight hanging from a force sensor, and distance and collision objects.
EYEBOT = """model: eyebot
objects:
  name: body
  type: shape
  shape: box
  size: [0.1, 0.1, 0.1]
  position: [0, 0, 0.05]
  dynamic: true
  mass: 1
  color: [0.8, 0.2, 0.2]
  children:
    - {name: eye, type: vision_sensor, position: [0.06, 0, 0], resolution: [32, 24],
       fov_deg: 60, near: 0.01, far: 3}
    - {name: led, type: led, position: [0, 0, 0.06], radius: 0.01, color: [0, 1, 0]}
    - {name: cam, type: blob_camera, position: [0, 0, 0.08], range: 3, fov_deg: 360}
    - name: hook
      type: force_sensor
      position: [0.0, 0.0, 0.05]
      children:
        - {name: weight, type: shape, shape: box, size: [0.02, 0.02, 0.02], dynamic: true,
           mass: 0.5, position: [0, 0, 0.02], color: [0.2, 0.2, 0.9]}
    - {name: near, type: distance, between: [":", everything_else]}
    - {name: touch, type: collision, between: [":", everything_else]}
"""

# Three robots in a row along x, facing +x: #0 sees #1's back, #1 sees #2's.
WORLD = """simulation: {physics: box2d, time_step: 0.1, seed: 1}
arena: {size: 4}
objects:
  - {name: wall, type: shape, shape: box, size: [0.1, 2, 0.3], position: [1.5, 0, 0.15],
     color: [0.9, 0.9, 0.1]}
models:
  - {model: eyebot.yaml, position: [-0.6, 0, 0]}
  - {model: eyebot.yaml, position: [-0.2, 0, 0]}
  - {model: eyebot.yaml, position: [0.2, 0, 0]}
"""


def read_png(path):
    """An 8-bit RGB PNG (what the program writes) as an (H, W, 3) uint8 array."""
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
            assert (depth, color) == (8, 2), "8-bit RGB"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * 3
    out = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1)
        line = line.astype(np.int32)
        cur = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            a = cur[x - 3] if x >= 3 else 0
            b = prev[x]
            c = prev[x - 3] if x >= 3 else 0
            if f == 0:
                p = 0
            elif f == 1:
                p = a
            elif f == 2:
                p = b
            elif f == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 255
        out[y] = cur
        prev = cur
    return out.reshape(height, width, 3).astype(np.uint8)


class SensorArraysTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.TemporaryDirectory()
        pathlib.Path(self.folder.name, "eyebot.yaml").write_text(EYEBOT)
        self.path = str(pathlib.Path(self.folder.name, "w.yaml"))
        pathlib.Path(self.path).write_text(WORLD)

    def tearDown(self):
        self.folder.cleanup()

    def test_robot_images_are_the_programs_snapshots_of_the_same_sensor(self):
        w = swarmsim.World(self.path)
        self.assertEqual(w.vision_sensor_names("eyebot"), ["eye"])
        w.step(3)
        images = w.vision_images("eyebot")
        self.assertEqual(images.shape, (3, 24, 32, 3))
        self.assertEqual(images.dtype, np.uint8)
        depth = w.vision_depths("eyebot", "eye")
        self.assertEqual((depth.shape, depth.dtype), ((3, 24, 32), np.float32))
        # Robot #0 sees #1's red back 0.3 m ahead (0.4 m apart, 0.05 + 0.06 of bodies and
        # mount): the centre pixel is red and about 0.29 m away.
        centre = images[0, 12, 16].astype(int)
        self.assertGreater(centre[0], 2 * centre[1], centre)
        self.assertAlmostEqual(float(depth[0, 12, 16]), 0.4 - 0.05 - 0.06, delta=0.02)
        # The same as one sensor by path, and out= fills the caller's array.
        np.testing.assert_array_equal(w.vision_image("/eyebot#1/eye"), images[1])
        out = np.empty((3, 24, 32, 3), dtype=np.uint8)
        self.assertIs(w.vision_images(out=out), out)
        np.testing.assert_array_equal(out, images)
        with self.assertRaises(ValueError):
            w.vision_images(out=np.empty((3, 24, 32, 3)))   # float64
        with self.assertRaises(ValueError):
            w.vision_images(sensor="nose")
        # The program's snapshot through the same sensor: taken in the record phase of
        # step 2, the state the sensor rendered at the sense phase of step 3.
        with tempfile.TemporaryDirectory() as out_dir:
            code, text = run([BINARY, "run", self.path, "--steps", "2", "--camera",
                              "/eyebot#1/eye", "--snapshot-every", "2", "--no-rays", "--out",
                              out_dir, "--quiet"])
            self.assertEqual(code, 0, text)
            snapshot = read_png(pathlib.Path(out_dir, "snapshots", "step_000002.png"))
        self.assertEqual(snapshot.shape, (24, 32, 3))
        np.testing.assert_array_equal(images[1], snapshot)

    def test_a_scene_vision_sensor_by_path(self):
        w = swarmsim.World(world("visual_servo.yaml"))
        w.step()
        image = w.vision_image("/overhead")
        self.assertEqual(image.shape, (96, 128, 3))
        filtered = w.vision_image("/overhead", filtered=True)
        self.assertEqual(filtered.shape, (96, 128, 3))
        self.assertFalse(np.array_equal(image, filtered), "the chain's segmented image")
        with self.assertRaises(ValueError) as e:
            w.vision_image("/overhed")
        self.assertIn("overhead", str(e.exception))   # the suggestion

    def test_blob_cameras_see_the_other_robots_leds(self):
        w = swarmsim.World(self.path)
        w.step()
        blobs = w.blob_cameras("eyebot")
        # In a row, the middle robot (its hanging weight at the cameras' height) hides
        # each end robot's LED from the other end: #0 sees #1, #1 sees #0 and #2.
        self.assertEqual(list(blobs["offsets"]), [0, 1, 3, 4])
        self.assertEqual(blobs["color"].shape, (4, 3))
        np.testing.assert_allclose(blobs["color"], np.tile([0, 1, 0], (4, 1)))
        self.assertEqual(list(blobs["robot"]), [1, 2, 0, 1] if blobs["bearing"][1] < blobs["bearing"][2]
                         else [1, 0, 2, 1])
        np.testing.assert_allclose(blobs["distance"], 0.4, atol=0.02)
        # Ahead (+x) of #0 at bearing 0, behind #2 at bearing pi.
        self.assertAlmostEqual(blobs["bearing"][0], 0, delta=0.05)
        self.assertAlmostEqual(abs(blobs["bearing"][3]), np.pi, delta=0.05)

    def test_force_sensors_hold_the_weight(self):
        w = swarmsim.World(self.path)
        self.assertEqual(w.force_sensor_names("eyebot"), ["hook"])
        w.step(3)
        f = w.force_sensors("eyebot")
        self.assertEqual(f.shape, (3, 1, 6))
        self.assertTrue(np.all(np.isfinite(f)), f)
        np.testing.assert_array_equal(w.force_sensors_broken("eyebot"), np.zeros((3, 1), bool))
        out = np.empty((3, 1, 6))
        w.force_sensors(out=out)
        np.testing.assert_array_equal(out, f)

    def test_distance_and_collision_objects(self):
        w = swarmsim.World(self.path)
        w.step()
        d = w.distances()
        self.assertEqual(d["names"], ["/eyebot#0/near", "/eyebot#1/near", "/eyebot#2/near"])
        self.assertTrue(np.all(d["found"]))
        # Neighbours' bodies 0.4 m apart centre to centre: 0.3 m between faces.
        np.testing.assert_allclose(d["distance"], 0.3, atol=0.02)
        self.assertEqual(d["p1"].shape, (3, 3))
        c = w.collisions()
        self.assertEqual(len(c["names"]), 3)
        self.assertFalse(np.any(c["colliding"]))
        self.assertEqual(c["points"].shape, (0, 3))


if __name__ == "__main__":
    unittest.main()
