// The report's 3D view: the trained model drawn by Spark (a three.js Gaussian-splat
// renderer) with the capture's cameras as frustums in the same scene. Bundled by esbuild
// with three and Spark into one script (scripts/install_node_tools.sh); the page (app.js)
// finds it as window.SaresgsViewer.
//
// Cameras come as the dataset holds them, in world coordinates: a world-to-camera rotation
// R (row-major 3x3), translation t, pixel intrinsics fx, fy, cx, cy (OpenCV: x right, y
// down, z forward). three.js cameras look down -z with y up, so a camera's world rotation
// is R^T diag(1, -1, -1) and its centre -R^T t.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { SparkRenderer, SplatMesh } from "@sparkjsdev/spark";

const ROLE_COLORS = {
  initial: 0x2f6fde,
  chosen: 0xe8741c,
  test: 0x1f9e55,
  candidate: 0x9aa0a6,
};

function cameraPose(cam) {
  const R = cam.R;
  const t = cam.t;
  // centre C = -R^T t
  const C = new THREE.Vector3(
    -(R[0][0] * t[0] + R[1][0] * t[1] + R[2][0] * t[2]),
    -(R[0][1] * t[0] + R[1][1] * t[1] + R[2][1] * t[2]),
    -(R[0][2] * t[0] + R[1][2] * t[1] + R[2][2] * t[2]),
  );
  // camera axes in world coordinates: rows of R
  const x = new THREE.Vector3(R[0][0], R[0][1], R[0][2]);
  const y = new THREE.Vector3(R[1][0], R[1][1], R[1][2]);
  const z = new THREE.Vector3(R[2][0], R[2][1], R[2][2]);
  const basis = new THREE.Matrix4().makeBasis(x, y.clone().negate(), z.clone().negate());
  const q = new THREE.Quaternion().setFromRotationMatrix(basis);
  return { C, x, y, z, q };
}

// OpenGL projection with the camera's own pixel intrinsics (principal point included).
function projectionFor(cam, near, far) {
  const w = cam.width;
  const h = cam.height;
  const m = new THREE.Matrix4();
  m.set(
    (2 * cam.fx) / w, 0, 1 - (2 * cam.cx) / w, 0,
    0, (2 * cam.fy) / h, (2 * cam.cy) / h - 1, 0,
    0, 0, -(far + near) / (far - near), (-2 * far * near) / (far - near),
    0, 0, -1, 0,
  );
  return m;
}

function labelSprite(text, color) {
  const c = document.createElement("canvas");
  c.width = 64;
  c.height = 64;
  const g = c.getContext("2d");
  g.fillStyle = "#" + color.toString(16).padStart(6, "0");
  g.beginPath();
  g.arc(32, 32, 30, 0, 2 * Math.PI);
  g.fill();
  g.fillStyle = "#ffffff";
  g.font = "bold 34px sans-serif";
  g.textAlign = "center";
  g.textBaseline = "middle";
  g.fillText(text, 32, 34);
  const tex = new THREE.CanvasTexture(c);
  // a fixed size on screen, whatever the distance
  const mat = new THREE.SpriteMaterial({ map: tex, depthTest: false, transparent: true, sizeAttenuation: false });
  const s = new THREE.Sprite(mat);
  s.renderOrder = 10;
  return s;
}

function frustumGeometry(cam, depth) {
  // the image corners at `depth` in camera coordinates (OpenCV), joined to the centre
  const corners = [
    [0, 0],
    [cam.width, 0],
    [cam.width, cam.height],
    [0, cam.height],
  ].map(([u, v]) => new THREE.Vector3(((u - cam.cx) / cam.fx) * depth, ((v - cam.cy) / cam.fy) * depth, depth));
  const o = new THREE.Vector3(0, 0, 0);
  const pts = [];
  for (let i = 0; i < 4; ++i) pts.push(o, corners[i], corners[i], corners[(i + 1) % 4]);
  // a tick on the image's top edge marks "up"
  const top = corners[0].clone().add(corners[1]).multiplyScalar(0.5);
  pts.push(top, top.clone().add(new THREE.Vector3(0, -0.25 * depth * (cam.height / cam.fy), 0)));
  return new THREE.BufferGeometry().setFromPoints(pts);
}

function cameraObject(cam, depth, color) {
  // OpenCV camera frame to world: columns x, y, z of R^T
  const { C, x, y, z } = cameraPose(cam);
  const g = new THREE.Group();
  const m = new THREE.Matrix4().makeBasis(x, y, z);
  m.setPosition(C);
  g.matrixAutoUpdate = false;
  g.matrix.copy(m);
  const lines = new THREE.LineSegments(frustumGeometry(cam, depth), new THREE.LineBasicMaterial({ color }));
  g.add(lines);
  return { group: g, lines };
}

export async function createViewer(canvas, opts) {
  const cams = opts.cameras || [];
  const background = new THREE.Color(opts.background[0], opts.background[1], opts.background[2]);
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setClearColor(background, 1);
  const scene = new THREE.Scene();
  const spark = new SparkRenderer({
    renderer,
    // match saresgs's rasterizer: 0.3 px^2 added to every projected covariance, z-depth
    // sorting, a 3-sigma footprint and alpha below 1/255 skipped, no level of detail
    preBlurAmount: opts.eps2d ?? 0.3,
    blurAmount: 0,
    maxStdDev: 3,
    minAlpha: 1 / 255,
    sortRadial: false,
    enableLod: false,
  });
  scene.add(spark);

  const mesh = new SplatMesh({ fileBytes: opts.model.bytes, fileType: opts.model.type });
  await mesh.initialized;
  scene.add(mesh);

  // scene extent from the cameras, to size frustums and the far plane
  const centres = cams.map((c) => cameraPose(c).C);
  const box = new THREE.Box3().setFromPoints(centres.length ? centres : [new THREE.Vector3()]);
  const extent = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-6);
  const near = opts.near ?? 0.01 * extent;
  const far = 100 * extent;
  const frustumDepth = 0.06 * extent;

  const camera = new THREE.PerspectiveCamera(50, canvas.width / canvas.height, near, far);
  const up = new THREE.Vector3();
  for (const c of cams) up.add(cameraPose(c).y.clone().negate());
  if (up.lengthSq() < 1e-12) up.set(0, 1, 0);
  camera.up.copy(up.normalize());

  const markers = [];
  const pickables = [];
  const cameraLayer = new THREE.Group();
  scene.add(cameraLayer);
  cams.forEach((cam, i) => {
    const color = ROLE_COLORS[cam.role] ?? ROLE_COLORS.candidate;
    const obj = cameraObject(cam, frustumDepth, color);
    cameraLayer.add(obj.group);
    const ball = new THREE.Mesh(
      new THREE.SphereGeometry(0.18 * frustumDepth, 8, 6),
      new THREE.MeshBasicMaterial({ color }),
    );
    ball.position.copy(centres[i]);
    ball.userData.index = i;
    cameraLayer.add(ball);
    pickables.push(ball);
    let label = null;
    if (cam.order != null) {
      label = labelSprite(String(cam.order), color);
      label.position.copy(centres[i]).addScaledVector(cameraPose(cam).y, -0.45 * frustumDepth);
      label.scale.setScalar(0.045);
      cameraLayer.add(label);
    }
    markers.push({ obj, ball, label, baseColor: color });
  });

  const controls = new OrbitControls(camera, canvas);
  controls.enableDamping = false;

  function lookFrom(i) {
    const cam = cams[i];
    const { C, z } = cameraPose(cam);
    const target = C.clone().addScaledVector(z, 0.5 * extent);
    camera.position.copy(C);
    controls.target.copy(target);
    camera.fov = (2 * Math.atan(cam.height / (2 * cam.fy)) * 180) / Math.PI;
    camera.updateProjectionMatrix();
    controls.update();
  }
  // From outside the capture: above and behind the cameras' centroid, all of them in view.
  function overview() {
    const c = new THREE.Vector3();
    for (const p of centres) c.add(p);
    c.multiplyScalar(1 / Math.max(1, centres.length));
    let radius = 0;
    for (const p of centres) radius = Math.max(radius, p.distanceTo(c));
    radius = Math.max(radius, 1e-6);
    const forward = new THREE.Vector3();
    for (const cam of cams) forward.add(cameraPose(cam).z);
    forward.addScaledVector(camera.up, -forward.dot(camera.up));
    if (forward.lengthSq() < 1e-12) forward.set(1, 0, 0).addScaledVector(camera.up, -camera.up.x);
    forward.normalize();
    camera.position.copy(c).addScaledVector(camera.up, 1.2 * radius).addScaledVector(forward, -2.2 * radius);
    controls.target.copy(c);
    camera.fov = 50;
    camera.updateProjectionMatrix();
    controls.update();
  }

  // Start where a person would look first: through one of the dataset's cameras.
  if (cams.length) lookFrom(opts.startCamera ?? 0);

  let exact = null; // a dataset camera drawn exactly (no orbit), until the user moves
  let size = { w: canvas.clientWidth || canvas.width, h: canvas.clientHeight || canvas.height };
  function resize(w, h) {
    size = { w, h };
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  resize(canvas.width, canvas.height);

  controls.addEventListener("start", () => {
    if (exact) {
      exact = null;
      camera.updateProjectionMatrix();
    }
  });

  const raycaster = new THREE.Raycaster();
  let down = null;
  canvas.addEventListener("pointerdown", (e) => (down = [e.clientX, e.clientY]));
  canvas.addEventListener("pointerup", (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
    const r = canvas.getBoundingClientRect();
    const p = new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(p, camera);
    const hit = raycaster.intersectObjects(pickables, false)[0];
    if (hit) {
      const i = hit.object.userData.index;
      lookFrom(i);
      if (opts.onPick) opts.onPick(i);
    }
  });

  // Drawn on demand (a camera move, Spark's sort finishing), not every frame: a report
  // left open in a tab, or a software-rendering test browser, then costs nothing.
  let frames = 0;
  let queued = false;
  let dirtySince = 0; // Spark changes (sorts landed) since the last draw
  function draw() {
    dirtySince = 0;
    renderer.render(scene, camera);
    frames += 1;
  }
  function requestDraw() {
    if (queued) return;
    queued = true;
    requestAnimationFrame(() => {
      queued = false;
      draw();
    });
  }
  spark.onDirty = () => {
    dirtySince += 1;
    requestDraw();
  };
  controls.addEventListener("change", requestDraw);
  const animationFrame = () => new Promise((r) => requestAnimationFrame(r));
  // Draws until Spark has sorted for this viewpoint and nothing changed for `quiet` frames
  // (its sort runs in a worker and lands a frame or more later), at most `limitMs`.
  async function settle(quiet = 3, limitMs = 30000) {
    const t0 = performance.now();
    let calm = 0;
    while (calm < quiet && performance.now() - t0 < limitMs) {
      dirtySince = 0;
      draw();
      await animationFrame();
      const sorted = !spark.sorting && !spark.sortDirty && spark.activeSplats > 0;
      calm = sorted && dirtySince === 0 ? calm + 1 : 0;
    }
  }
  requestDraw();

  return {
    splatCount: mesh.packedSplats ? mesh.packedSplats.numSplats : undefined,
    // Recolours cameras: colors[i] a 0xRRGGBB or null for the role's colour.
    setCameraColors(colors) {
      markers.forEach((m, i) => {
        const c = colors && colors[i] != null ? colors[i] : m.baseColor;
        m.obj.lines.material.color.setHex(c);
        m.ball.material.color.setHex(c);
      });
      requestDraw();
    },
    // Where dataset camera i's marker is on the canvas, in CSS pixels from its top-left
    // corner (null when behind the viewer): what a click must hit to look through it.
    markerOnScreen(i) {
      const p = centres[i].clone().project(camera);
      if (p.z < -1 || p.z > 1) return null;
      const r = canvas.getBoundingClientRect();
      return { x: ((p.x + 1) / 2) * r.width, y: ((1 - p.y) / 2) * r.height };
    },
    // The camera the viewer looks from, in world coordinates.
    position() {
      return camera.position.toArray();
    },
    showCameras(on) {
      cameraLayer.visible = on;
      requestDraw();
    },
    lookFrom(i) {
      lookFrom(i);
      requestDraw();
    },
    requestDraw,
    overview() {
      overview();
      requestDraw();
    },
    // Draws dataset camera i exactly (its pixel size, intrinsics and pose, cameras hidden)
    // and returns the picture: a PNG data URL, or with `raw` {width, height, rgba: base64
    // RGBA rows top-down}, what the browser test compares with saresgs's render of the view.
    async capture(i, { raw = false } = {}) {
      const cam = cams[i];
      const prevSize = size;
      const shown = cameraLayer.visible;
      cameraLayer.visible = false;
      resize(cam.width, cam.height);
      const { C, q } = cameraPose(cam);
      camera.position.copy(C);
      camera.quaternion.copy(q);
      camera.updateMatrixWorld(true);
      camera.projectionMatrix.copy(projectionFor(cam, near, far));
      camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
      exact = i;
      await settle();
      renderer.render(scene, camera);
      let result;
      if (raw) {
        // rows bottom-up from WebGL, returned top-down as base64 RGBA
        const gl = renderer.getContext();
        gl.bindBuffer(gl.PIXEL_PACK_BUFFER, null); // Spark leaves its readback buffer bound
        const px = new Uint8Array(cam.width * cam.height * 4);
        gl.readPixels(0, 0, cam.width, cam.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
        const flipped = new Uint8Array(px.length);
        const row = cam.width * 4;
        for (let y = 0; y < cam.height; ++y) flipped.set(px.subarray((cam.height - 1 - y) * row, (cam.height - y) * row), y * row);
        let bin = "";
        for (let k = 0; k < flipped.length; k += 0x8000) bin += String.fromCharCode.apply(null, flipped.subarray(k, k + 0x8000));
        result = { width: cam.width, height: cam.height, rgba: btoa(bin) };
      } else {
        result = canvas.toDataURL("image/png");
      }
      cameraLayer.visible = shown;
      resize(prevSize.w, prevSize.h);
      lookFrom(i);
      requestDraw();
      return result;
    },
    resize,
  };
}

if (typeof window !== "undefined") {
  window.SaresgsViewer = { createViewer, threeRevision: THREE.REVISION };
}
