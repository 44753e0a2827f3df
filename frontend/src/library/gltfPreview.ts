// A segment's glTF export played in place: the .glb the service writes, loaded with three.js's
// GLTFLoader as Unreal, Unity or a web viewer would, its first animation run by an
// AnimationMixer on the file's own skeleton. Shows what a studio gets before it downloads.

import * as THREE from "three";
import { type GLTF, GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { clear, h } from "../ui/dom";

export interface GlbSummary {
  joints: number;
  animations: { name: string; duration: number; tracks: number }[];
}

/** What a loaded glTF holds: how many joints its first animation moves, its animations. */
export function summarise(gltf: GLTF): GlbSummary {
  const first = gltf.animations[0];
  // A track is named "<node>.<property>"; the node names are the joints it moves.
  const joints = new Set(first ? first.tracks.map((track) => track.name.slice(0, track.name.lastIndexOf("."))) : []);
  return {
    joints: joints.size,
    animations: gltf.animations.map((clip) => ({ name: clip.name, duration: clip.duration, tracks: clip.tracks.length })),
  };
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
    scene.add(new THREE.HemisphereLight("#ffffff", "#2a3140", 2.5), gltf.scene, new THREE.SkeletonHelper(gltf.scene));
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const size = Math.max(box.getSize(new THREE.Vector3()).length(), 0.1);
    const centre = box.getCenter(new THREE.Vector3());
    const camera = new THREE.PerspectiveCamera(40, 1, size * 0.01, size * 100);
    camera.position.set(centre.x + size * 0.8, centre.y + size * 0.3, centre.z + size * 1.2);
    camera.lookAt(centre);
    const mixer = new THREE.AnimationMixer(gltf.scene);
    if (gltf.animations[0]) mixer.clipAction(gltf.animations[0]).play();
    const clock = new THREE.Clock();
    let raf = 0;
    const tick = () => {
      const width = stage.clientWidth || 320;
      const height = stage.clientHeight || 240;
      renderer.setSize(width, height, false);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
      mixer.update(clock.getDelta());
      renderer.render(scene, camera);
      raf = requestAnimationFrame(tick);
    };
    raf = requestAnimationFrame(tick);
    return () => {
      cancelAnimationFrame(raf);
      mixer.stopAllAction();
      renderer.dispose();
    };
  }

  stop(): void {
    this.stopCurrent();
    this.stopCurrent = () => undefined;
  }
}
