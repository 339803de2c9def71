#!/usr/bin/env python3
"""collision_lab.read_bag on bags collision_lab_node recorded (test/python/read_bag.test;
a rostest node, not a pytest file): each run's bag gives the Run that collision_lab.run
gives for the same scene (events as numpy arrays, value for value; the summary's values that
the bag holds, under the same keys)."""
import math
import os
import time
import unittest

import numpy as np
import rospy

import collision_lab
from collision_lab._bag import BAG_SUMMARY_KEYS
from collision_lab.srv import RunScene, RunSceneRequest

INF = float('inf')
SCENES = {
    'pi': dict(masses=[100.0, 1.0, INF], positions=[2.0, 1.0, 0.0], velocities=[-1.0, 0.0, 0.0]),
    'collapse': dict(masses=[1.0, 1.0, 1.0], positions=[2.0, 1.0, 0.0], velocities=[-1.0, 0.0, 0.0],
                     restitution=[0.05]),
    'engine': dict(masses=[1.0, 2.0, 3.0, 4.0, 5.0], positions=[4.0, 3.0, 2.0, 1.0, 0.0],
                   velocities=[-1.0, 0.5, 0.0, 0.2, 1.0]),
}


def same(a, b):
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


class ReadBag(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node('read_bag_test')
        service = '/collision_lab/collision_lab_node/run_scene'
        rospy.wait_for_service(service)
        cls.call = rospy.ServiceProxy(service, RunScene)

    def recorded(self, name, scene):
        """The bag of the node's run of `scene`, once the node has closed it."""
        answer = self.call(RunSceneRequest(run_id='py_' + name, **scene))
        self.assertTrue(answer.ok, answer.rejected)
        path = answer.summary.bag_path
        while not os.path.exists(path):  # renamed from .bag.active when closed
            time.sleep(0.05)
        return answer.summary, path

    def check(self, name):
        scene = SCENES[name]
        summary, path = self.recorded(name, scene)
        bag = collision_lab.read_bag(path)
        restitution = scene.get('restitution', [1.0])
        run = collision_lab.run(scene['masses'], scene['positions'], scene['velocities'], restitution)
        self.assertEqual(bag.model, run.model)
        self.assertEqual(bag.summary['collision_count'], summary.collision_count)
        self.assertEqual(bag.summary['run_id'], 'py_' + name)
        self.assertEqual(bag.summary['bag_path'], path)
        # The values the bag holds and the CLI's report gives (run() fills in the rest of its keys).
        compared = [key for key in BAG_SUMMARY_KEYS if key in run.report['summary'] and key != 'compute_time_s']
        self.assertGreaterEqual(len(compared), 15)
        self.assertEqual(set(bag.summary) - set(run.summary), {'run_id', 'student', 'bag_path'})
        for key in compared:
            self.assertTrue(same(bag.summary[key], run.summary[key]), (key, bag.summary[key], run.summary[key]))
        self.assertEqual(set(bag.events), set(run.events))
        for key, values in run.events.items():
            if values.dtype.kind == 'f':
                np.testing.assert_array_equal(bag.events[key], values, err_msg=key)
            else:
                self.assertEqual(bag.events[key].tolist(), values.tolist(), key)
        np.testing.assert_array_equal(bag.masses, np.array(scene['masses']))
        np.testing.assert_array_equal(bag.initial_velocities, np.array(scene['velocities']))
        self.assertEqual(list(bag.to_pandas().columns), list(run.to_pandas().columns))
        return bag

    def test_pi_billiard(self):
        bag = self.check('pi')
        self.assertEqual(len(bag.events['time']), 31)
        self.assertIn('predicted_velocities_after', bag.events)

    def test_spiral_collapse(self):
        bag = self.check('collapse')
        self.assertEqual(bag.events['kind'].tolist()[-1], 'collapse')
        self.assertTrue(bag.summary['collapsed'])

    def test_event_engine(self):
        bag = self.check('engine')
        self.assertEqual(bag.model, 'event_engine')
        self.assertEqual(bag.events['positions'].shape, (bag.summary['collision_count'], 5))

    def test_many_bodies_beyond_the_full_state(self):
        # CollisionEvent carries per-body arrays up to FULL_STATE_MAX_BODIES (64) bodies:
        # beyond, read_bag's per-body arrays are run()'s read-only view of one NaN (no events
        # x bodies memory), the scalars and pair fields still the run's, and state_at gives
        # every body's state, as run()'s does.
        n = 70
        scene = dict(masses=[1.0 + (i % 3) for i in range(n)], positions=[float(n - i) for i in range(n)],
                     velocities=[-1.0] + [0.0] * (n - 2) + [1.0])
        summary, path = self.recorded('many', scene)
        bag = collision_lab.read_bag(path)
        run = collision_lab.run(scene['masses'], scene['positions'], scene['velocities'])
        events = summary.collision_count
        self.assertGreater(events, 0)
        self.assertEqual(bag.events['positions'].shape, (events, n))
        self.assertTrue(np.isnan(bag.events['velocities_after']).all())
        self.assertEqual(bag.events['velocities_after'].strides, (0, 0))
        for key in ('index', 'pair_index', 'time', 'position', 'total_energy', 'pair_velocities_after'):
            np.testing.assert_array_equal(bag.events[key], run.events[key], err_msg=key)
        self.assertEqual(bag.names[-1], '#69')
        masses = np.array(scene['masses'])
        momentum = float(np.sum(masses * np.array(scene['velocities'])))
        for k in (1, events // 2, events):
            x, v = bag.state_at(k)
            x_run, v_run = run.state_at(k)
            np.testing.assert_array_equal(v, v_run, err_msg=str(k))
            np.testing.assert_array_equal(x, x_run, err_msg=str(k))
            # Elastic, no walls: the momentum is the start's, to rounding.
            self.assertLessEqual(abs(float(np.sum(masses * v)) - momentum), 1e-12 * float(np.sum(masses)))
        # After the last impact: RunSummary's final velocities, recorded from the engine's state.
        self.assertEqual(bag.state_at(events)[1].tolist(), list(summary.final_velocities))
        self.assertFalse([c for c in bag.to_pandas().columns if c.startswith(('v_', 'x_'))])


if __name__ == '__main__':
    import rosunit
    rosunit.unitrun('collision_lab', 'read_bag_test', ReadBag)
