// The 3D view: the montage.glb that mmh wrote (the montage with its spatial markers, every take
// warped to the reference timeline and as recorded) played by three.js, in sync with a scrubber
// in montage frames: at montage frame k every node shows its own frame (report/montage_clock.h):
// the montage its k-th, a warped take the reference frame t that k was played from, a recorded
// take its own frame w_K(t) (the chosen take: the very frame the montage plays).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export const kBackground = 0xf4f4f4;

// True when WebGL runs on a CPU rasteriser (SwiftShader, llvmpipe).
function softwareRenderer() {
  const gl = document.createElement('canvas').getContext('webgl2');
  if (!gl) return false;
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}

export class View3d {
  // montage: {frames, node (the montage node's glTF name)}; clock: {reference: [t per montage
  // frame], takes: [[take K's frame per montage frame]]}; onFrame(frame, t) after every move.
  constructor(host, montage, clock, onFrame) {
    this.montage = montage;
    this.clock = clock;
    this.onFrame = onFrame;
    host.append(Object.assign(document.createElement('h2'), { textContent: '3D view' }));
    host.append(Object.assign(document.createElement('p'), {
      className: 'note',
      textContent: 'Left: the montage (grey: spatial markers); then each take, warped to the ' +
        'reference timeline (front row) and as recorded (back row). At montage frame k the ' +
        'warped takes show the reference frame t that k was played from and the recorded takes ' +
        'their own frame w_K(t) (the chosen take: the frame the montage plays); drag to orbit.',
    }));
    this.canvas = document.createElement('canvas');
    this.canvas.width = 900;
    this.canvas.height = 420;
    this.canvas.className = 'view3d';
    host.append(this.canvas);
    const controls = document.createElement('div');
    controls.className = 'controls';
    this.play = Object.assign(document.createElement('button'), { textContent: 'play' });
    this.scrubber = Object.assign(document.createElement('input'), {
      type: 'range', min: '0', max: String(montage.frames - 1), step: '1', value: '0',
    });
    this.scrubber.id = 'scrubber';
    this.label = document.createElement('span');
    controls.append(this.play, this.scrubber, this.label);
    host.append(controls);

    // Multisampling triples the cost of a frame in a software rasteriser (SwiftShader: a scrub
    // step 14 ms without, 41-55 ms with, bench/README.md); GPUs get it.
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: !softwareRenderer() });
    this.renderer.setPixelRatio(1);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(kBackground);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x707070, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, 3, 2);
    this.scene.add(sun);
    this.camera = new THREE.PerspectiveCamera(40, this.canvas.width / this.canvas.height, 0.01, 100);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.render());
    this.playing = false;
    this.play.addEventListener('click', () => this.toggle());
    this.scrubber.addEventListener('input', () => this.showFrame(Number(this.scrubber.value)));
  }

  load(buffer) {
    return new Promise((resolve, reject) => {
      new GLTFLoader().parse(buffer, '', (gltf) => {
        this.root = gltf.scene;
        this.scene.add(this.root);
        this.clip = gltf.animations.find((a) => a.name === 'montage') || gltf.animations[0];
        this.mixer = new THREE.AnimationMixer(this.root);
        // One action per node, each set to its own time (the node's clock).
        const byNode = new Map();
        for (const track of this.clip.tracks) {
          const node = track.name.slice(0, track.name.lastIndexOf('.'));
          if (!byNode.has(node)) byNode.set(node, []);
          byNode.get(node).push(track);
        }
        const name = THREE.PropertyBinding.sanitizeNodeName(this.montage.node);
        // The clocks are the first object's; layered objects were recorded while its montage
        // played (no time warp): their nodes show frame k of their own tracks.
        const object = name.slice(0, -'_montage'.length);
        const ofObject = new RegExp(`^${object}_take_(\\d+)_(warped|recorded)$`);
        this.clocks = [];
        for (const [node, tracks] of byNode) {
          const action = this.mixer.clipAction(new THREE.AnimationClip(node, -1, tracks));
          // Held at its end: a repeating action would wrap the last frame back to the first.
          action.setLoop(THREE.LoopOnce, 1);
          action.clampWhenFinished = true;
          action.play();
          const take = node.match(ofObject);
          this.clocks.push({
            node, action, times: tracks[0].times,
            role: take ? take[2] : node === name ? 'montage' : 'layer', take: take ? Number(take[1]) - 1 : -1,
          });
        }
        this.node = this.root.getObjectByName(name);
        const track = this.clip.tracks.find((t) => t.name === `${name}.position`);
        if (!this.node || !track) throw new Error(`montage.glb has no animated node ${name}`);
        this.times = track.times;  // the montage's keyframe times: frame k plays at times[k]
        if (this.clock.reference.length !== this.times.length) {
          throw new Error(`montage.glb has ${this.times.length} montage frames, the timeline ${this.clock.reference.length}`);
        }
        this.frame(this.root);
        this.showFrame(0);
        resolve();
      }, reject);
    });
  }

  // Frames the camera on the scene's bounds at time 0, seen from the front and above.
  frame(root) {
    this.mixer.setTime(0);
    root.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(root);
    const center = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    const grid = new THREE.GridHelper(size * 1.5, 20, 0xb0b0b0, 0xd8d8d8);
    grid.position.set(center.x, box.min.y, center.z);
    this.scene.add(grid);
    // Far enough that the whole width (glTF x: the columns) fits the horizontal field of view.
    const extent = box.getSize(new THREE.Vector3());
    const vertical = THREE.MathUtils.degToRad(this.camera.fov);
    const horizontal = 2 * Math.atan(Math.tan(vertical / 2) * this.camera.aspect);
    const distance = 1.15 * Math.max(extent.x / 2 / Math.tan(horizontal / 2) + extent.z / 2,
      extent.y / 2 / Math.tan(vertical / 2));
    this.camera.position.copy(center).add(new THREE.Vector3(0, 0.5, 0.87).multiplyScalar(distance));
    this.camera.near = size / 200;
    this.camera.far = size * 20;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
  }

  // Moves every node to its own frame at montage frame `frame` (clamped) and draws.
  showFrame(frame) {
    const k = Math.max(0, Math.min(this.times.length - 1, Math.round(frame)));
    const t = this.clock.reference[k];
    this.current = k;
    this.scrubber.value = String(k);
    for (const c of this.clocks) {
      const index = c.role === 'warped' ? t : c.role === 'recorded' ? this.clock.takes[c.take][k] : k;
      c.action.time = c.times[Math.min(index, c.times.length - 1)];
    }
    this.mixer.update(0);
    this.label.textContent = ` frame ${k} / ${this.times.length - 1}  (${this.times[k].toFixed(3)} s)` +
      `  reference frame ${t}; takes at ${this.clock.takes.map((w, K) => `${K + 1}: ${w[k]}`).join(', ')}`;
    this.render();
    this.onFrame(k, t);
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  toggle() {
    this.playing = !this.playing;
    this.play.textContent = this.playing ? 'pause' : 'play';
    if (!this.playing) return;
    const start = performance.now() / 1000 - this.times[this.current];
    const step = () => {
      if (!this.playing) return;
      const t = performance.now() / 1000 - start;
      let k = this.current;
      while (k + 1 < this.times.length && this.times[k + 1] <= t) ++k;
      if (k + 1 >= this.times.length) this.toggle();
      this.showFrame(k);
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }

  // For the browser test: the montage node's local pose (glTF axes) after the last move, and
  // every animated node's (by glTF node name).
  montagePose() {
    const nodes = {};
    for (const c of this.clocks) {
      const node = this.root.getObjectByName(c.node);
      nodes[c.node] = { position: node.position.toArray(), quaternion: node.quaternion.toArray() };
    }
    return { position: this.node.position.toArray(), quaternion: this.node.quaternion.toArray(), nodes };
  }

  // For the browser test: pixels of the drawn canvas that differ from the background.
  foregroundPixels() {
    this.render();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
    const pixels = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    // The drawing buffer holds sRGB-encoded output: compare with the background's sRGB bytes.
    const ref = [(kBackground >> 16) & 255, (kBackground >> 8) & 255, kBackground & 255];
    let count = 0;
    for (let i = 0; i < pixels.length; i += 4) {
      if (Math.abs(pixels[i] - ref[0]) + Math.abs(pixels[i + 1] - ref[1]) + Math.abs(pixels[i + 2] - ref[2]) > 24) ++count;
    }
    return { count, total: w * h };
  }

  // Scrubbing cost: milliseconds to move to a frame and draw it (finished on the GPU), over
  // `steps` frames spread over the montage: {mean, median, p95, max}.
  scrubMilliseconds(steps) {
    const gl = this.renderer.getContext();
    const probe = new Uint8Array(4);
    const times = [];
    for (let i = 0; i < steps; ++i) {
      const t0 = performance.now();
      this.showFrame(Math.floor((i * (this.times.length - 1)) / Math.max(1, steps - 1)));
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, probe);
      times.push(performance.now() - t0);
    }
    const sorted = times.slice().sort((a, b) => a - b);
    const at = (q) => sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))];
    return { mean: times.reduce((a, b) => a + b, 0) / steps, median: at(0.5), p95: at(0.95),
      max: sorted[sorted.length - 1] };
  }
}
