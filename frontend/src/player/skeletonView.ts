// The 3D skeleton: joints as spheres, bones as cylinders (instanced, so one draw call
// each), a floor grid and an orbit camera that can follow the root. It renders on demand
// only, which keeps an idle review page from burning a CPU core.
//
// A skeleton of many joints (markers, fingers, props) is drawn with coarser spheres and
// cylinders so a pose costs about the same to draw whatever the joint count, and posing
// allocates nothing per joint. Beyond MAX_JOINTS, what the service refuses, nothing is drawn.

import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import type { Skeleton } from "../api/types";

const LEFT = new THREE.Color("#4fc3f7");
const RIGHT = new THREE.Color("#ffb74d");
const CENTRE = new THREE.Color("#e0e6ef");

const CMU_LIMBS = "(clavicle|humerus|radius|wrist|hand|fingers|thumb|hipjoint|femur|tibia|foot|toes)";
const LEFT_LIMB = new RegExp(`^l${CMU_LIMBS}`, "i");
const RIGHT_LIMB = new RegExp(`^r${CMU_LIMBS}`, "i");

/** The most joints the service admits by default (CUTROOM_MAX_JOINTS); /api/me/ says the actual limit. */
export const MAX_JOINTS = 1000;
/** Above this many joints, spheres and cylinders get fewer faces. */
const DETAILED_JOINTS = 64;

/** Which side of the body a joint is on: CMU "lfemur", BVH "LeftUpLeg"/"LHipJoint", "mixamorig:RightArm",
 * Kinect "elbow_left", Plug-in Gait "LELB". */
export function sideOf(name: string): "left" | "right" | "centre" {
  const bare = name.replace(/^.*:/, "");
  // Case-sensitive for the single-letter prefix, so "Root" or "LowerBack" stay central.
  const letter = /^L[A-Z_]/.test(bare) ? "left" : /^R[A-Z_]/.test(bare) ? "right" : null;
  if (letter) return letter;
  // Kinect joints name the side last: "elbow_left", "ElbowLeft".
  if (/^left/i.test(bare) || /left$/i.test(bare) || LEFT_LIMB.test(bare) || /[._]l$/i.test(bare)) return "left";
  if (/^right/i.test(bare) || /right$/i.test(bare) || RIGHT_LIMB.test(bare) || /[._]r$/i.test(bare)) return "right";
  return "centre";
}

export class SkeletonView {
  readonly canvas: HTMLCanvasElement;
  private readonly renderer: THREE.WebGLRenderer;
  private readonly scene = new THREE.Scene();
  private readonly camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
  private readonly controls: OrbitControls;
  private readonly joints: THREE.InstancedMesh;
  private readonly bones: THREE.InstancedMesh;
  private readonly boneList: [number, number][];
  private readonly radius: number;
  private lastRoot: THREE.Vector3 | null = null;
  private readonly floor: THREE.Object3D;
  private readonly cell: number;
  private pending = false;
  follow = true;

  constructor(
    private readonly container: HTMLElement,
    private readonly skeleton: Skeleton,
    maxJoints = MAX_JOINTS,
  ) {
    if (skeleton.joints.length > maxJoints) throw new TooManyJoints(skeleton.joints.length, maxJoints);
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.canvas = this.renderer.domElement;
    container.appendChild(this.canvas);
    const height = skeleton.height > 0 ? skeleton.height : 1.8;
    this.radius = height * 0.018;
    // Units are the capture's own (cm, inches, metres…): scale clipping to the body.
    this.camera.near = height * 0.01;
    this.camera.far = height * 60;
    this.camera.updateProjectionMatrix();
    this.scene.background = new THREE.Color("#161a21");
    this.scene.add(new THREE.HemisphereLight("#ffffff", "#2a3140", 2.2));
    const sun = new THREE.DirectionalLight("#ffffff", 1.4);
    sun.position.set(height, height * 3, height * 2);
    this.scene.add(sun);
    this.cell = height / 2;
    this.floor = floor(height);
    this.scene.add(this.floor);
    this.boneList = skeleton.parents.flatMap((p, j) => (p >= 0 ? [[p, j] as [number, number]] : []));
    const detailed = skeleton.joints.length <= DETAILED_JOINTS;
    const sphere = detailed ? new THREE.SphereGeometry(1, 14, 10) : new THREE.SphereGeometry(1, 6, 4);
    const cylinder = new THREE.CylinderGeometry(1, 1, 1, detailed ? 10 : 4, 1, !detailed);
    this.joints = this.instanced(sphere, skeleton.joints.length, (i) => skeleton.joints[i]);
    this.bones = this.instanced(cylinder, this.boneList.length, (i) => skeleton.joints[this.boneList[i][1]]);
    this.camera.position.set(height * 0.95, height * 0.8, height * 2.0);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.target.set(0, height * 0.45, 0);
    this.controls.enableDamping = false;
    this.controls.addEventListener("change", () => this.requestRender());
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  private instanced(geometry: THREE.BufferGeometry, count: number, nameOf: (i: number) => string): THREE.InstancedMesh {
    const material = new THREE.MeshStandardMaterial({ roughness: 0.55, metalness: 0.05 });
    const mesh = new THREE.InstancedMesh(geometry, material, Math.max(count, 1));
    mesh.count = count;
    for (let i = 0; i < count; i++) {
      const side = sideOf(nameOf(i));
      mesh.setColorAt(i, side === "left" ? LEFT : side === "right" ? RIGHT : CENTRE);
    }
    mesh.frustumCulled = false;
    this.scene.add(mesh);
    return mesh;
  }

  /** Show one pose: `pose` is (n_joints, 3) flattened, in the capture's units, Y up. A point
   * not seen in this frame (a marker take's gap: NaN) is hidden, and so are its links. */
  setPose(pose: Float32Array): void {
    const { m, q, a, b, mid, scale } = SCRATCH;
    const r = this.radius;
    for (let j = 0; j < this.skeleton.joints.length; j++) {
      a.fromArray(pose, j * 3);
      if (Number.isNaN(a.x + a.y + a.z)) {
        m.makeScale(0, 0, 0);
      } else {
        m.compose(a, q.identity(), b.set(r * 1.25, r * 1.25, r * 1.25));
      }
      this.joints.setMatrixAt(j, m);
    }
    for (let i = 0; i < this.boneList.length; i++) {
      const [p, c] = this.boneList[i];
      a.fromArray(pose, p * 3);
      b.fromArray(pose, c * 3);
      if (Number.isNaN(a.x + a.y + a.z + b.x + b.y + b.z)) {
        this.bones.setMatrixAt(i, m.makeScale(0, 0, 0));
        continue;
      }
      const length = a.distanceTo(b);
      mid.copy(a).add(b).multiplyScalar(0.5);
      q.setFromUnitVectors(UP, length > 1e-9 ? b.sub(a).divideScalar(length) : UP);
      m.compose(mid, q, scale.set(length > 1e-9 ? r * 0.8 : 0, length, r * 0.8));
      this.bones.setMatrixAt(i, m);
    }
    this.joints.instanceMatrix.needsUpdate = true;
    this.bones.instanceMatrix.needsUpdate = true;
    const root = seenPoint(pose);
    if (root) this.followRoot(root);
    this.requestRender();
  }

  /** Keep the root in frame by sliding camera and target with it over the floor. */
  private followRoot(root: THREE.Vector3): void {
    if (this.lastRoot && this.follow) {
      const delta = root.clone().sub(this.lastRoot).setY(0);
      this.camera.position.add(delta);
      this.controls.target.add(delta);
      this.controls.update();
    } else if (!this.lastRoot) {
      const offset = this.camera.position.clone().sub(this.controls.target);
      this.controls.target.set(root.x, this.controls.target.y, root.z);
      this.camera.position.copy(this.controls.target).add(offset);
      this.controls.update();
    }
    this.lastRoot = root;
    // The floor plane is finite: keep it under the actor (its lines are in world
    // coordinates, so moving it by whole cells changes nothing on screen).
    const cell = this.cell;
    this.floor.position.x = Math.round(root.x / cell) * cell;
    this.floor.position.z = Math.round(root.z / cell) * cell;
  }

  /** Put the floor at height `y` (the take's lowest joint) and aim the camera above it. */
  setFloor(y: number): void {
    const dy = y - this.floor.position.y;
    if (Math.abs(dy) < 1e-9) return;
    this.floor.position.y = y;
    this.camera.position.y += dy;
    this.controls.target.y += dy;
    this.controls.update();
    this.requestRender();
  }

  requestRender(): void {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.renderer.render(this.scene, this.camera);
    });
  }

  private resize(): void {
    const { clientWidth: w, clientHeight: h } = this.container;
    if (w === 0 || h === 0) return;
    this.renderer.setSize(w, h, false);
    this.canvas.style.width = "100%";
    this.canvas.style.height = "100%";
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  dispose(): void {
    this.controls.dispose();
    this.renderer.dispose();
    this.canvas.remove();
  }
}

/** The root (joint 0), or for a pose whose first point is a gap the first point seen; null
 * when nothing is seen in this frame. */
export function seenPoint(pose: Float32Array): THREE.Vector3 | null {
  for (let j = 0; j + 2 < pose.length; j += 3) {
    if (!Number.isNaN(pose[j] + pose[j + 1] + pose[j + 2])) return new THREE.Vector3().fromArray(pose, j);
  }
  return null;
}

/** A skeleton the player will not draw: more joints than the service admits. */
export class TooManyJoints extends Error {
  constructor(
    readonly count: number,
    readonly limit: number,
  ) {
    super(`${count.toLocaleString("en-US")} joints; the player draws at most ${limit.toLocaleString("en-US")}, as many as the service admits`);
  }
}

const UP = new THREE.Vector3(0, 1, 0);
// Reused by every setPose: posing a frame allocates nothing per joint.
const SCRATCH = {
  m: new THREE.Matrix4(),
  q: new THREE.Quaternion(),
  a: new THREE.Vector3(),
  b: new THREE.Vector3(),
  mid: new THREE.Vector3(),
  scale: new THREE.Vector3(),
};

/**
 * A floor with grid lines drawn in the fragment shader: a line primitive crossing the
 * camera's near plane is dropped by some software rasterisers (headless Chromium's
 * SwiftShader), a triangle is not. Lines every half body height, a stronger one every
 * 2.5, fading into the background with distance.
 */
function floor(height: number): THREE.Object3D {
  const size = height * 200;
  const material = new THREE.ShaderMaterial({
    uniforms: {
      cell: { value: height / 2 },
      fadeDistance: { value: height * 14 },
      background: { value: new THREE.Color("#161a21") },
      base: { value: new THREE.Color("#1b2029") },
      minor: { value: new THREE.Color("#323a47") },
      major: { value: new THREE.Color("#4b5669") },
    },
    vertexShader: `
      varying vec3 vWorld;
      void main() {
        vec4 world = modelMatrix * vec4(position, 1.0);
        vWorld = world.xyz;
        gl_Position = projectionMatrix * viewMatrix * world;
      }`,
    fragmentShader: `
      uniform float cell;
      uniform float fadeDistance;
      uniform vec3 background, base, minor, major;
      varying vec3 vWorld;
      float gridLine(vec2 coord) {
        vec2 g = abs(fract(coord - 0.5) - 0.5) / fwidth(coord);
        return 1.0 - min(min(g.x, g.y), 1.0);
      }
      void main() {
        vec3 colour = mix(base, minor, gridLine(vWorld.xz / cell));
        colour = mix(colour, major, gridLine(vWorld.xz / (cell * 5.0)));
        float fade = smoothstep(fadeDistance * 0.3, fadeDistance, distance(vWorld.xz, cameraPosition.xz));
        gl_FragColor = vec4(mix(colour, background, fade), 1.0);
        #include <colorspace_fragment>
      }`,
  });
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(size, size), material);
  plane.rotation.x = -Math.PI / 2;
  return plane;
}
