from segmentation.models import DetectionRun
from tests.segmentation.base import BaseTestCase


class RunsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.url = f"/api/captures/{self.capture.pk}/runs/"
        self.login(self.bob)

    def test_it_lists_methods_with_their_parameter_schema(self):
        methods = {m["name"]: m for m in self.client.get("/api/methods/").json()}
        param = methods["bone_angle"]["params"]["param"]
        self.assertEqual((param["type"], param["default"], param["min"], param["max"]), ("float", 0.5, 0.0, 1.0))

    def test_it_no_longer_lists_the_default_options_that_lost_out_of_sample(self):
        methods = {m["name"]: m for m in self.client.get("/api/methods/").json()}
        params = methods["default"]["params"]
        self.assertIn("support", params)
        self.assertFalse({"tempo", "short_activity", "short_uniformity"} & set(params))

    def test_it_refuses_a_default_run_asking_for_a_removed_option_by_name(self):
        r = self.client.post(self.url, {"method": "default", "params": {"tempo": True}}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("unknown parameter for method 'default'", r.json()["params"]["tempo"][0])

    def test_it_queues_a_run_with_validated_params(self):
        r = self.client.post(self.url, {"method": "bone_angle", "params": {"param": "0.3"}}, format="json")
        self.assertEqual(r.status_code, 202)
        run = DetectionRun.objects.get(pk=r.json()["id"])
        self.assertEqual((run.status, run.params["param"]), ("queued", 0.3))
        self.assertIn("cutoff_hz", run.params)

    def test_it_refuses_an_unknown_method(self):
        r = self.client.post(self.url, {"method": "magic"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("unknown segmenter 'magic'", r.json()["method"][0])

    def test_it_refuses_a_parameter_out_of_range(self):
        r = self.client.post(self.url, {"method": "bone_angle", "params": {"param": -1}}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("got -1", r.json()["params"]["param"][0])

    def test_it_refuses_an_unknown_parameter(self):
        r = self.client.post(self.url, {"method": "bone_angle", "params": {"sigma": 2}}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("sigma", r.json()["params"])

    def test_it_refuses_garbage_params(self):
        r = self.client.post(self.url, {"method": "bone_angle", "params": "lots"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("params", r.json())

    def test_it_lists_runs(self):
        runs = self.client.get(self.url).json()
        self.assertEqual([r["status"] for r in runs], ["ready"])
        self.assertEqual(len(runs[0]["candidates"]), 3)

    def test_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.post(self.url, {"method": "bone_angle"}, format="json").status_code, 404)
        self.assertFalse(DetectionRun.objects.filter(status="queued").exists())
