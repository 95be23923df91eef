#!/usr/bin/env python3
"""Tests of the procedural RGB-D scene generator (training/scenes.py and the modules it uses).

Run: /usr/bin/python3 training/test_scenes.py (ctest runs it as training_scenes)."""

import os
import struct
import sys
import tempfile
import unittest
import zlib
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))
import archive_photos  # noqa: E402
import photo_folder  # noqa: E402
import raytracer  # noqa: E402
import scene_sampler  # noqa: E402
import scenes  # noqa: E402
import textures  # noqa: E402
from raytracer import Atmosphere, Camera, Light, Scene, SceneObject  # noqa: E402
from shapes import Box, Quad, Sphere, ground_plane  # noqa: E402
from textures import Material  # noqa: E402

SMALL = (96, 72)
SEEDS = (0, 1, 2, 3, 4, 5, 6, 7, 10 ** 9, 10 ** 9 + 1)

RED = np.array([0.6, 0.05, 0.05], dtype=np.float32)
BLUE = np.array([0.05, 0.05, 0.6], dtype=np.float32)
GREY = np.array([0.3, 0.3, 0.3], dtype=np.float32)
GREEN = np.array([0.05, 0.6, 0.05], dtype=np.float32)


def level_camera(width=160, height=120, eye_height=1.5):
    return Camera(width, height, fov_x_deg=60.0, position=np.array([0.0, eye_height, 0.0]))


def pixel_of(camera, point):
    """(row, col) of a world point seen by a level camera (no pitch, roll or yaw)."""
    x, y, z = np.asarray(point, dtype=np.float64) - camera.position
    col = camera.focal * x / z + camera.width / 2 - 0.5
    row = camera.focal * -y / z + camera.height / 2 - 0.5
    return int(round(row)), int(round(col))


def plain_scene(camera, objects, sun_direction=(0.0, 1.0, 0.0)):
    light = Light(np.asarray(sun_direction, dtype=np.float64), np.full(3, 2.0, np.float32),
                  np.full(3, 0.3, np.float32))
    atmosphere = Atmosphere(np.array([0.1, 0.2, 0.6], np.float32), np.array([0.6, 0.7, 0.8], np.float32), 0.0)
    return Scene(camera, objects, light, atmosphere)


def wall_and_box_scene(box_first=False):
    """A box (front face at z = 3.5) at eye height in front of a wall at z = 10."""
    camera = level_camera()
    ground = SceneObject(ground_plane(), Material(GREY), False)
    wall = SceneObject(Quad((0, 0, 10), (1, 0, 0), (0, 1, 0), np.inf, np.inf), Material(BLUE), False)
    box = SceneObject(Box((0, 1.5, 4), (0.5, 0.5, 0.5)), Material(RED))
    sphere = SceneObject(Sphere((0.7, 1.5, 6), 0.5), Material(GREEN))
    objects = [box, sphere, ground, wall] if box_first else [ground, wall, sphere, box]
    return plain_scene(camera, objects)


class HandBuiltScenes(unittest.TestCase):
    def test_box_occludes_wall_with_exact_disparity(self):
        scene = wall_and_box_scene()
        radiance, disparity = raytracer.render(scene)
        box_pixel = pixel_of(scene.camera, (0, 1.5, 3.5))
        wall_pixel = pixel_of(scene.camera, (-3, 2.5, 10))
        self.assertAlmostEqual(float(disparity[box_pixel]), 1 / 3.5, places=5)
        self.assertAlmostEqual(float(disparity[wall_pixel]), 1 / 10, places=6)
        self.assertGreater(disparity[box_pixel], disparity[wall_pixel])
        red, _, blue = radiance[:, box_pixel[0], box_pixel[1]]
        self.assertGreater(red, 3 * blue, 'the box, not the wall behind it, must give the colour')
        red, _, blue = radiance[:, wall_pixel[0], wall_pixel[1]]
        self.assertGreater(blue, 3 * red)

    def test_nearer_box_hides_part_of_the_sphere_behind_it(self):
        scene = wall_and_box_scene()
        _, disparity = raytracer.render(scene)
        hidden = pixel_of(scene.camera, (0.4, 1.5, 3.5))      # on the box, in front of the sphere
        visible = pixel_of(scene.camera, (1.1, 1.5, 6.0))     # the sphere's right side, beside the box
        self.assertAlmostEqual(float(disparity[hidden]), 1 / 3.5, places=5)
        self.assertGreater(disparity[visible], 1 / 6.5)
        self.assertLess(disparity[visible], 1 / 5.0)

    def test_drawing_order_does_not_matter(self):
        _, first = raytracer.render(wall_and_box_scene(box_first=False))
        _, second = raytracer.render(wall_and_box_scene(box_first=True))
        np.testing.assert_array_equal(first, second)

    def test_ground_disparity_is_exact_and_grows_downwards(self):
        camera = level_camera(eye_height=2.0)
        scene = plain_scene(camera, [SceneObject(ground_plane(), Material(GREY), False)])
        _, disparity = raytracer.render(scene)
        rows = np.arange(camera.height)
        below = rows + 0.5 > camera.height / 2
        expected = (rows[below] + 0.5 - camera.height / 2) / camera.focal / 2.0   # y_n / eye height
        np.testing.assert_allclose(disparity[below, 0], expected, rtol=1e-5)
        self.assertTrue(np.all(np.diff(disparity[below, 0]) > 0), 'ground must recede upwards')
        self.assertTrue(np.all(disparity[~below] == 0), 'above the horizon is sky: disparity 0')

    def test_box_casts_a_shadow_on_the_ground(self):
        camera = level_camera()
        ground = SceneObject(ground_plane(), Material(GREY), False)
        box = SceneObject(Box((0, 0.6, 4), (0.3, 0.3, 0.3)), Material(RED))
        radiance, _ = raytracer.render(plain_scene(camera, [ground, box], sun_direction=(0, 1, 0)))
        shaded = radiance[:, pixel_of(camera, (0, 0, 4.2))[0], pixel_of(camera, (0, 0, 4.2))[1]]
        sunlit = radiance[:, pixel_of(camera, (1.5, 0, 4.2))[0], pixel_of(camera, (1.5, 0, 4.2))[1]]
        self.assertLess(shaded.sum() * 2, sunlit.sum())

    def test_cutout_mask_lets_the_background_through(self):
        camera = level_camera()
        wall = SceneObject(Quad((0, 0, 10), (1, 0, 0), (0, 1, 0), np.inf, np.inf), Material(BLUE), False)
        mask = np.zeros((4, 4), dtype=bool)
        mask[:, :2] = True                                     # only the left half is solid
        cutout = SceneObject(Quad((0, 1.5, 5), (1, 0, 0), (0, 1, 0), 1.0, 1.0, mask), Material(RED))
        _, disparity = raytracer.render(plain_scene(camera, [wall, cutout]))
        self.assertAlmostEqual(float(disparity[pixel_of(camera, (-0.5, 1.5, 5))]), 0.2, places=5)
        self.assertAlmostEqual(float(disparity[pixel_of(camera, (0.5, 1.5, 5))]), 0.1, places=6)


def mirrored(value, size):
    """Plain reference of the mirrored repeat into [0, size]."""
    value = value % (2 * size)
    return 2 * size - value if value > size else value


class Texturing(unittest.TestCase):
    def test_bilinear_sampling_matches_a_plain_loop(self):
        seed = 7
        rng = np.random.default_rng(seed)
        image = rng.integers(0, 256, (3, 12, 16), dtype=np.uint8)
        crop = (2.0, 3.0, 9.0, 7.0)
        x = rng.uniform(-30, 30, 60).astype(np.float32)
        y = rng.uniform(-30, 30, 60).astype(np.float32)
        got = textures.sample_bilinear(torch.from_numpy(image), crop, x, y)
        for i in range(x.size):
            px = mirrored(float(x[i]), crop[2] - 1) + crop[0]
            py = mirrored(float(y[i]), crop[3] - 1) + crop[1]
            x0, y0 = int(px), int(py)
            fx, fy = px - x0, py - y0
            x1, y1 = min(x0 + 1, 15), min(y0 + 1, 11)
            texel = image.astype(np.float64) / 255
            value = ((texel[:, y0, x0] * (1 - fx) + texel[:, y0, x1] * fx) * (1 - fy)
                     + (texel[:, y1, x0] * (1 - fx) + texel[:, y1, x1] * fx) * fy)
            np.testing.assert_allclose(got[:, i], value ** 2, atol=1e-4,
                                       err_msg=f'seed {seed}, sample {i} at ({x[i]}, {y[i]})')

    def test_samples_past_the_last_texel_read_the_edge(self):
        # A crop scaled to a coarse level: 2.5 + 5.5 ends past the 7-texel-wide level, and
        # the mirrored repeat takes x = 4.5 to texel 7.0, one past the last.
        image = np.arange(3 * 4 * 7, dtype=np.uint8).reshape(3, 4, 7)
        x = np.full(5, 4.5, np.float32)
        got = textures.sample_bilinear(torch.from_numpy(image), (2.5, 0.0, 5.5, 4.0), x, np.zeros(5, np.float32))
        edge = (image[:, 0, 6].astype(np.float64) / 255) ** 2
        np.testing.assert_allclose(got, np.repeat(edge[:, None], 5, axis=1), atol=1e-6)
        # Huge coordinates, whose float32 mirrored repeat falls up to 64 texels below 0.
        huge = np.array([-2.2536290e+08, -2.1325616e+08, 3.2158978e+07], np.float32)
        self.assertLess(float(textures.mirror(huge, 6.0).min()), 0)
        got = textures.sample_bilinear(torch.from_numpy(image), (0.0, 0.0, 7.0, 4.0), huge, np.zeros(3, np.float32))
        self.assertEqual(got.shape, (3, 3))

    def test_mip_levels_average_two_by_two_blocks(self):
        seed = 3
        image = np.random.default_rng(seed).integers(0, 256, (40, 36, 3), dtype=np.uint8)
        levels = textures.mip_pyramid(image)
        self.assertEqual([tuple(level.shape) for level in levels], [(3, 40, 36), (3, 20, 18), (3, 10, 9)])
        blocks = image.astype(np.float64).reshape(20, 2, 18, 2, 3).mean(axis=(1, 3))
        np.testing.assert_allclose(levels[1].numpy().transpose(1, 2, 0), blocks, atol=0.5,
                                   err_msg=f'seed {seed}')


class RandomScenes(unittest.TestCase):
    def test_same_seed_same_images(self):
        for seed in (3, 10 ** 9 + 3):
            with self.subTest(seed=seed):
                rgb_a, disparity_a = scenes.render_scene(seed, *SMALL)
                rgb_b, disparity_b = scenes.render_scene(seed, *SMALL)
                np.testing.assert_array_equal(rgb_a, rgb_b)
                np.testing.assert_array_equal(disparity_a, disparity_b)
        rgb_other, _ = scenes.render_scene(4, *SMALL)
        self.assertFalse(np.array_equal(rgb_other, scenes.render_scene(3, *SMALL)[0]))

    def test_shapes_and_types(self):
        rgb, disparity = scenes.render_scene(11, 64, 40)
        self.assertEqual(rgb.shape, (40, 64, 3))
        self.assertEqual(rgb.dtype, np.uint8)
        self.assertEqual(disparity.shape, (40, 64))
        self.assertEqual(disparity.dtype, np.float32)

    def test_disparity_positive_where_not_sky_and_zero_in_sky(self):
        for seed in SEEDS:
            with self.subTest(seed=seed):
                scene = scene_sampler.sample_scene(seed, *SMALL)
                gbuffer = raytracer.raycast(scene)
                _, disparity = scenes.render_scene(seed, *SMALL)
                surface = gbuffer.ids >= 0
                self.assertTrue(np.all(np.isfinite(disparity)))
                self.assertTrue(np.all(disparity[surface] > 0))
                self.assertTrue(np.all(disparity[~surface] == 0))
                self.assertLess(float(disparity.max()), 1 / raytracer.NEAR_CLIP + 1e-3)
                np.testing.assert_array_equal(disparity, raytracer.disparity_of(gbuffer))

    def test_scenes_are_varied(self):
        counts = [len(scene_sampler.sample_scene(seed, *SMALL).objects) for seed in range(8)]
        self.assertGreater(min(counts), 4, f'objects per scene: {counts}')
        shapes = {type(o.shape).__name__ for seed in range(8) for o in scene_sampler.sample_scene(seed, *SMALL).objects}
        self.assertEqual(shapes, {'Box', 'Sphere', 'Cylinder', 'Quad'})

    def test_images_are_not_flat(self):
        for seed in SEEDS[:4]:
            with self.subTest(seed=seed):
                rgb, _ = scenes.render_scene(seed, *SMALL)
                self.assertGreater(float(rgb.std()), 8.0)


class ValidationSplit(unittest.TestCase):
    def test_seed_split(self):
        self.assertFalse(photo_folder.is_validation_seed(0))
        self.assertFalse(photo_folder.is_validation_seed(10 ** 9 - 1))
        self.assertTrue(photo_folder.is_validation_seed(10 ** 9))

    def test_every_tenth_photo_of_each_folder_is_validation(self):
        photos = photo_folder.list_photos()
        train, val = photo_folder.list_photos('train'), photo_folder.list_photos('val')
        self.assertFalse(set(train) & set(val))
        self.assertEqual(sorted(train + val), photos)
        folders = {p.parent for p in photos}
        expected = sum(len([p for p in photos if p.parent == f]) // 10 for f in folders)
        self.assertEqual(len(val), expected)
        first_folder = sorted(p for p in photos if p.parent == sorted(folders)[0])
        self.assertEqual(photo_folder.photo_split(first_folder[9]), 'val')
        self.assertEqual(photo_folder.photo_split(first_folder[8]), 'train')

    def test_every_fifth_photo_is_ordinal_validation_and_no_training_texture(self):
        photos = photo_folder.list_photos()
        ordinal_val = {p for p in photos if photo_folder.ordinal_split(p) == 'val'}
        self.assertLessEqual(set(photo_folder.list_photos('val')), ordinal_val)  # the synthetic ones too
        folders = {p.parent for p in photos}
        self.assertEqual(len(ordinal_val), sum(len([p for p in photos if p.parent == f]) // 5 for f in folders))
        self.assertFalse(set(textures.texture_pool('train').paths) & ordinal_val)

    def test_texture_pools_are_disjoint_and_used_by_their_seeds(self):
        train, val = textures.texture_pool('train'), textures.texture_pool('val')
        self.assertFalse(set(train.paths) & set(val.paths))
        for seed, pool in ((5, train), (10 ** 9 + 5, val)):
            with self.subTest(seed=seed):
                owned = {id(p) for p in pool.pyramids}
                used = {id(o.material.pyramid) for o in scene_sampler.sample_scene(seed, *SMALL).objects
                        if o.material.pyramid is not None}
                self.assertTrue(used)
                self.assertLessEqual(used, owned)

    def test_a_root_of_linked_folders_splits_as_the_folders_do_and_archive_photos_train(self):
        """training/archive_photos.py's root: ../shared's folders linked, archive/ beside them."""
        shared = photo_folder.photo_root()
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp)
            (root / 'kodak24').symlink_to(shared / 'kodak24', target_is_directory=True)
            (root / 'archive').mkdir()
            for n in range(10):
                (root / 'archive' / f'photo_{n}.jpg').write_bytes(b'')
            photos = photo_folder.list_photos(root=root)
            linked = [p for p in photos if p.parent.name == 'kodak24']
            self.assertEqual([p.name for p in linked], [p.name for p in photo_folder.list_photos(root=shared / 'kodak24')])
            self.assertTrue(all(p.is_relative_to(root) for p in photos))
            for split in (photo_folder.photo_split, photo_folder.ordinal_split):
                self.assertEqual([split(p) for p in linked], [split(shared / 'kodak24' / p.name) for p in linked])
                self.assertEqual({split(p) for p in photos if p.parent.name == 'archive'}, {'train'})

    def test_every_second_archive_photo_labelled_last_is_holdout(self):
        """Counted among each HOLDOUT_GROUPS group's photos alone, by sorted name, so a
        later group leaves the earlier ones' parts as they were; the other archive photos
        train, and photo_split (the synthetic validation) is unchanged."""
        with tempfile.TemporaryDirectory() as tmp:
            archive = Path(tmp) / 'archive'
            archive.mkdir()
            names = ['a_photo.jpg', 'gcompris_x.jpg', 'hugin_a.jpg', 'kphotoalbum_b.jpg', 'lomiri_y.jpg',
                     'mate_z.jpg', 'plasma_1.jpg', 'plasma_2.png', 'tuxtype_c.jpg', 'zz.jpg']
            for name in names:
                (archive / name).write_bytes(b'')
            ordinal = {name: photo_folder.ordinal_split(archive / name) for name in names}
            self.assertEqual(sorted(n for n, s in ordinal.items() if s == 'holdout'),
                             ['kphotoalbum_b.jpg', 'mate_z.jpg', 'plasma_2.png'])
            self.assertEqual(set(ordinal.values()), {'train', 'holdout'})
            self.assertEqual({photo_folder.photo_split(archive / n) for n in names}, {'train'})

    def test_a_qt_resource_file_gives_back_its_files(self):
        """archive_photos.read_rcc on a version-3 resource file built here by the format: a
        folder holding a zlib-compressed file, a stored one and a zstd one (left out)."""
        names, tree, data = b'', b'', b''

        def name(text):
            nonlocal names
            offset = len(names)
            names += struct.pack('>HI', len(text), 0) + text.encode('utf-16-be')
            return offset

        def stored(content, compress=False):
            nonlocal data
            offset = len(data)
            body = struct.pack('>I', len(content)) + zlib.compress(content) if compress else content
            data += struct.pack('>I', len(body)) + body
            return offset

        def folder(name_offset, count, first):
            return struct.pack('>IHII', name_offset, 2, count, first) + bytes(8)

        def file(name_offset, flags, offset):
            return struct.pack('>IHHHI', name_offset, flags, 0, 0, offset) + bytes(8)

        photo = bytes(range(256)) * 4
        tree = (folder(0, 1, 1) + folder(name('res'), 3, 2) + file(name('a.webp'), 1, stored(photo, True))
                + file(name('b.txt'), 0, stored(b'plain')) + file(name('c.bin'), 4, stored(b'zstd')))
        header_size = 24
        blob = (b'qres' + struct.pack('>5I', 3, header_size, header_size + len(tree),
                                      header_size + len(tree) + len(data), 0) + tree + data + names)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / 'one.rcc'
            path.write_bytes(blob)
            self.assertEqual(archive_photos.read_rcc(path), {'res/a.webp': photo, 'res/b.txt': b'plain'})
            path.write_bytes(b'PK' + blob[2:])
            with self.assertRaisesRegex(SystemExit, 'one.rcc: not a Qt resource file'):
                archive_photos.read_rcc(path)

    def test_archive_names_are_unique_photos(self):
        names = archive_photos.archive_names()
        self.assertEqual(len(names), sum(len(photos) for *_, photos, _licence in archive_photos.SOURCES))
        self.assertTrue(all(Path(name).suffix in photo_folder.PHOTO_SUFFIXES for name in names))
        self.assertEqual(archive_photos.name_here('usa/navajo.webp'), ('usa/navajo.webp', 'usa_navajo.jpg'))

    def test_bad_paths_are_named_in_the_error(self):
        with self.assertRaisesRegex(ValueError, 'notes.txt'):
            photo_folder.photo_split(photo_folder.photo_root() / 'kodak24' / 'notes.txt')
        with tempfile.TemporaryDirectory() as empty:
            missing = os.path.join(empty, 'nowhere')
            with self.assertRaisesRegex(RuntimeError, 'nowhere'):
                photo_folder.list_photos(root=missing)
            with self.assertRaisesRegex(RuntimeError, 'no train photos'):
                photo_folder.list_photos('train', root=empty)


class Dataset(unittest.TestCase):
    def test_items_are_tensors_of_the_requested_size(self):
        dataset = scenes.SceneDataset(20, 3, (64, 48))
        self.assertEqual(len(dataset), 3)
        image, disparity = dataset[2]
        self.assertEqual(image.shape, (3, 48, 64))
        self.assertEqual(disparity.shape, (1, 48, 64))
        self.assertEqual(image.dtype, torch.float32)
        self.assertTrue(0 <= float(image.min()) and float(image.max()) <= 1)
        expected_rgb, expected_disparity = scenes.render_scene(22, 64, 48)
        np.testing.assert_array_equal(disparity[0].numpy(), expected_disparity)
        np.testing.assert_allclose(image.permute(1, 2, 0).numpy() * 255, expected_rgb, atol=1e-3)
        with self.assertRaises(IndexError):
            dataset[3]

    def test_a_range_may_not_mix_training_and_validation_seeds(self):
        with self.assertRaisesRegex(ValueError, 'mix'):
            scenes.SceneDataset(10 ** 9 - 1, 2)

    def test_dataloader_with_a_worker(self):
        loader = torch.utils.data.DataLoader(scenes.SceneDataset(30, 4, (48, 32)), batch_size=2, num_workers=1)
        batches = list(loader)
        self.assertEqual(len(batches), 2)
        self.assertEqual(tuple(batches[0][0].shape), (2, 3, 32, 48))
        _, expected = scenes.render_scene(33, 48, 32)
        np.testing.assert_array_equal(batches[1][1][1, 0].numpy(), expected)


class CommandLine(unittest.TestCase):
    def test_contact_sheet_is_written(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, 'sheet.png')
            self.assertEqual(scenes.main(['--contact-sheet', path, '--seeds', '1', '2']), 0)
            self.assertGreater(os.path.getsize(path), 1000)

    def test_failure_is_one_line_and_non_zero(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, 'missing', 'sheet.png')
            self.assertEqual(scenes.main(['--contact-sheet', path, '--seeds', '1']), 1)


if __name__ == '__main__':
    unittest.main(verbosity=2)
