// A segment's glTF export played in place: the .glb the service writes, loaded with three.js's
// GLTFLoader as Unreal, Unity or a web viewer would, its first animation run by an
// AnimationMixer on the file's own skeleton. Shows what a studio gets before it downloads.
//
// The skeleton is drawn from the nodes the animation moves, not from a skin: a clip of a BVH or
// AMC capture is an armature without a mesh, whose joints three.js loads as plain nodes, and
// the camera frames those joints over the whole clip (a bounding box of meshes alone would be
// empty, and the first pose alone would let a walk leave the view).

import * as THREE from "three";
import { type GLTF, GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { clear, h } from "../ui/dom";

export interface GlbSummary {
  joints: number;
  animations: { name: string; duration: number; tracks: number }[];
}

/** The names of the nodes the first animation moves: a track is named "<node>.<property>". */
function animatedNames(gltf: GLTF): Set<string> {
  const first = gltf.animations[0];
  return new Set(first ? first.tracks.map((track) => track.name.slice(0, track.name.lastIndexOf("."))) : []);
}

/** What a loaded glTF holds: how many joints its first animation moves, its animations. */
export function summarise(gltf: GLTF): GlbSummary {
  return {
    joints: animatedNames(gltf).size,
    animations: gltf.animations.map((clip) => ({ name: clip.name, duration: clip.duration, tracks: clip.tracks.length })),
  };
}

/** The skeleton's joints: the nodes the animation moves, and the bones of any skin. */
export function jointNodes(gltf: GLTF): THREE.Object3D[] {
  const names = animatedNames(gltf);
  const nodes: THREE.Object3D[] = [];
  gltf.scene.traverse((node) => {
    if (names.has(node.name) || (node as THREE.Bone).isBone) nodes.push(node);
  });
  return nodes;
}

/** Lines from each joint to its parent joint and a dot on each, posed from the nodes' world
 * matrices on every `update()`; drawn over any mesh so the skeleton always shows. */
export class JointLines {
  readonly object = new THREE.Group();
  private readonly pairs: [THREE.Object3D, THREE.Object3D][];
  private readonly lines: THREE.BufferAttribute;
  private readonly dots: THREE.BufferAttribute;
  private readonly point = new THREE.Vector3();

  constructor(private readonly joints: THREE.Object3D[]) {
    const set = new Set(joints);
    this.pairs = joints.flatMap((j) => (j.parent && set.has(j.parent) ? [[j.parent, j] as [THREE.Object3D, THREE.Object3D]] : []));
    this.lines = new THREE.BufferAttribute(new Float32Array(this.pairs.length * 6), 3);
    this.dots = new THREE.BufferAttribute(new Float32Array(joints.length * 3), 3);
    const lineGeometry = new THREE.BufferGeometry().setAttribute("position", this.lines);
    const dotGeometry = new THREE.BufferGeometry().setAttribute("position", this.dots);
    const lineMaterial = new THREE.LineBasicMaterial({ color: "#7ee2a8", depthTest: false, transparent: true });
    const dotMaterial = new THREE.PointsMaterial({ color: "#ffd666", size: 5, sizeAttenuation: false, depthTest: false, transparent: true });
    this.object.add(new THREE.LineSegments(lineGeometry, lineMaterial), new THREE.Points(dotGeometry, dotMaterial));
    this.object.renderOrder = 1;
    for (const child of this.object.children) child.frustumCulled = false;
  }

  update(): void {
    this.pairs.forEach(([a, b], i) => {
      this.lines.setXYZ(2 * i, ...this.world(a));
      this.lines.setXYZ(2 * i + 1, ...this.world(b));
    });
    this.joints.forEach((j, i) => this.dots.setXYZ(i, ...this.world(j)));
    this.lines.needsUpdate = true;
    this.dots.needsUpdate = true;
  }

  /** The joints' current world positions, in a box (empty without joints). */
  box(): THREE.Box3 {
    const box = new THREE.Box3();
    for (const j of this.joints) box.expandByPoint(j.getWorldPosition(this.point));
    return box;
  }

  private world(node: THREE.Object3D): [number, number, number] {
    node.getWorldPosition(this.point);
    return [this.point.x, this.point.y, this.point.z];
  }

  dispose(): void {
    for (const child of this.object.children) {
      const drawn = child as THREE.LineSegments | THREE.Points;
      drawn.geometry.dispose();
      (drawn.material as THREE.Material).dispose();
    }
  }
}

// Poses the framing looks at: this many per second of the clip, at most FRAME_SAMPLES_MAX.
const FRAME_SAMPLES_PER_S = 30;
const FRAME_SAMPLES_MAX = 240;

/** What the camera frames: the joints in every pose of the clip (sampled evenly from its
 * first frame to its last), so a walk or a jump stays in view as it travels, and any mesh as
 * first posed (a mesh's box alone is empty for an armature without one). Leaves the mixer at
 * the clip's start. */
export function frameBox(gltf: GLTF, skeleton: JointLines, mixer: THREE.AnimationMixer, duration: number): THREE.Box3 {
  const box = new THREE.Box3();
  const samples = duration > 0 ? Math.min(FRAME_SAMPLES_MAX, Math.max(2, Math.ceil(duration * FRAME_SAMPLES_PER_S) + 1)) : 1;
  for (let i = 0; i < samples; i++) {
    // The last sample stays a hair before the end: a looping action at its full duration
    // wraps around to the first pose.
    mixer.setTime(samples > 1 ? Math.min(duration * (i / (samples - 1)), duration * 0.9999) : 0);
    gltf.scene.updateMatrixWorld(true);
    box.union(skeleton.box());
  }
  mixer.setTime(0);
  gltf.scene.updateMatrixWorld(true);
  const meshes = new THREE.Box3().setFromObject(gltf.scene);
  if (!meshes.isEmpty()) box.union(meshes);
  return box;
}

export class GlbPreview {
  private stopCurrent: () => void = () => undefined;

  constructor(private readonly box: HTMLElement) {}

  async play(url: string, caption: string, id: string): Promise<GlbSummary> {
    this.stop();
    const gltf = await new GLTFLoader().loadAsync(url);
    const summary = summarise(gltf);
    const [first] = summary.animations;
    const stage = h("div", { class: "lib-stage" });
    const facts = `glTF · ${summary.joints} joints · ${first ? `${first.duration.toFixed(2)} s` : "no animation"}`;
    clear(this.box, stage, h("div", { class: "muted small", "data-testid": "preview-caption" }, `${caption} · ${facts}`));
    this.box.setAttribute("data-playing", id);
    this.box.setAttribute("data-gltf-joints", String(summary.joints));
    this.box.setAttribute("data-gltf-duration", first ? first.duration.toFixed(4) : "0");
    this.stopCurrent = this.animate(stage, gltf);
    return summary;
  }

  private animate(stage: HTMLElement, gltf: GLTF): () => void {
    let renderer: THREE.WebGLRenderer;
    try {
      renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    } catch {
      stage.append(h("p", { class: "muted" }, "WebGL is not available to draw the clip."));
      return () => undefined;
    }
    stage.append(renderer.domElement);
    const scene = new THREE.Scene();
    scene.background = new THREE.Color("#161a21");
    const skeleton = new JointLines(jointNodes(gltf));
    scene.add(new THREE.HemisphereLight("#ffffff", "#2a3140", 2.5), gltf.scene, skeleton.object);
    const mixer = new THREE.AnimationMixer(gltf.scene);
    if (gltf.animations[0]) mixer.clipAction(gltf.animations[0]).play();
    const box = frameBox(gltf, skeleton, mixer, gltf.animations[0]?.duration ?? 0);
    const extent = box.isEmpty() ? new THREE.Vector3(1, 1, 1) : box.getSize(new THREE.Vector3());
    // The performer's height as first posed (the framed box also holds where they travel).
    const first = skeleton.box();
    this.box.setAttribute("data-gltf-height", (first.isEmpty() ? 0 : first.max.y - first.min.y).toFixed(3));
    const size = Math.max(extent.length(), 0.1);
    const centre = box.isEmpty() ? new THREE.Vector3() : box.getCenter(new THREE.Vector3());
    const camera = new THREE.PerspectiveCamera(40, 1, size * 0.01, size * 100);
    camera.position.set(centre.x + size * 0.8, centre.y + size * 0.3, centre.z + size * 1.2);
    camera.lookAt(centre);
    const clock = new THREE.Clock();
    let raf = 0;
    const tick = () => {
      const width = stage.clientWidth || 320;
      const height = stage.clientHeight || 240;
      renderer.setSize(width, height, false);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
      mixer.update(clock.getDelta());
      gltf.scene.updateMatrixWorld(true);
      skeleton.update();
      renderer.render(scene, camera);
      raf = requestAnimationFrame(tick);
    };
    raf = requestAnimationFrame(tick);
    return () => {
      cancelAnimationFrame(raf);
      mixer.stopAllAction();
      skeleton.dispose();
      renderer.dispose();
    };
  }

  stop(): void {
    this.stopCurrent();
    this.stopCurrent = () => undefined;
  }
}
