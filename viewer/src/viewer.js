// The Acyclic viewer page: shows what acyclic-view computed (window.ACYCLIC_DATA,
// format acyclic.view/1): the scene, the robot's collision shapes, each
// stance's contacts and forces, the centre of mass, along the plan or the
// trajectory. It computes no kinematics: every pose comes from the C++ side.
//
// Its state is window.acyclicViewer (for tests and scripts): loaded, error,
// stances, frames, shapes, robotMeshes, current, drawn, renders, and the
// methods setStance(i), setFrame(i), setTime(t), play(), pause().
//
// URL options: ?stance=I  ?frame=I  ?t=SECONDS  ?strip=I,J,K (stances side by
// side, like the paper's figure 5)  &hud=0 (no controls: for stills).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const COLORS = {
  robot: 0x5d7fa3,
  obstacle: 0xb9a27f,
  floor: 0xf2f2f2,
  supporting: 0x27ae60,
  geometric: 0xf39c12,
  com: 0xc0392b,
  force: 0x8e44ad,
  surface: 0x7f8c8d,
};
const FORCE_SCALE = 0.0012; // m per N: the robot's weight (570 N) is 0.68 m

const state = {
  loaded: false,
  error: null,
  scenario: null,
  stances: 0,
  frames: 0,
  shapes: 0,
  robotMeshes: 0,
  obstacles: 0,
  mode: 'stance', // 'stance', 'frame' or 'strip'
  current: null, // {mode, index, stance, t}
  drawn: null, // {contacts, supporting, geometric, arrows, com}
  strip: [],
  renders: 0,
  playing: false,
};
window.acyclicViewer = state;

function fail(message) {
  state.error = message;
  const el = document.getElementById('error');
  el.textContent = 'Acyclic viewer: ' + message;
  el.style.display = 'block';
  console.error('acyclic viewer:', message);
}

function shapeGeometry(s) {
  switch (s.kind) {
    case 'box':
      return new THREE.BoxGeometry(s.size[0], s.size[1], s.size[2]);
    case 'sphere':
      return new THREE.SphereGeometry(s.radius, 20, 14);
    case 'capsule':
      // three's capsule and cylinder run along y; ours along local z.
      return new THREE.CapsuleGeometry(s.radius, s.length, 6, 16).rotateX(Math.PI / 2);
    case 'cylinder':
      return new THREE.CylinderGeometry(s.radius, s.radius, s.length, 24).rotateX(Math.PI / 2);
    default:
      throw new Error('unknown shape kind ' + s.kind + ' (' + s.name + ')');
  }
}

function setPose(obj, poses, i) {
  const k = 7 * i;
  obj.position.set(poses[k], poses[k + 1], poses[k + 2]);
  obj.quaternion.set(poses[k + 3], poses[k + 4], poses[k + 5], poses[k + 6]);
}

const v3 = (a) => new THREE.Vector3(a[0], a[1], a[2]);

// A filled convex polygon (triangle fan) lifted 1.5 mm off its surface so it
// does not flicker against it, with its outline.
function polygonObject(points, color, opacity) {
  const group = new THREE.Group();
  const lift = 0.0015;
  const verts = [];
  for (let i = 1; i + 1 < points.length; ++i)
    for (const p of [points[0], points[i], points[i + 1]]) verts.push(p[0], p[1], p[2] + lift);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(verts, 3));
  group.add(new THREE.Mesh(g, new THREE.MeshBasicMaterial({
    color, transparent: true, opacity, side: THREE.DoubleSide, depthWrite: false })));
  const outline = new THREE.BufferGeometry().setFromPoints(points.map((p) => new THREE.Vector3(p[0], p[1], p[2] + lift)));
  group.add(new THREE.LineLoop(outline, new THREE.LineBasicMaterial({ color })));
  return group;
}

function main() {
  const data = window.ACYCLIC_DATA;
  if (!data) return fail('data.js is missing or did not load: write the page with acyclic-view');
  if (data.format !== 'acyclic.view/1') return fail('data.js: format ' + data.format + ', expected acyclic.view/1');
  const params = new URLSearchParams(location.search);
  if (params.get('hud') === '0') document.body.classList.add('nohud');

  state.scenario = data.scenario.name;
  state.stances = data.stances.length;
  state.frames = data.frames.length;
  state.shapes = data.robot.shapes.length;
  state.obstacles = data.obstacles.length;
  state.stanceSummary = data.stances.map((s) => ({
    contacts: s.contacts.length,
    supporting: s.contacts.filter((c) => c.supporting).length,
    valid: s.valid,
    feasible: s.feasible,
  }));

  const container = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(container.clientWidth, container.clientHeight);
  renderer.setClearColor(0xf4f5f7);
  container.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  const sky = new THREE.HemisphereLight(0xffffff, 0x8a8070, 1.6);
  sky.position.set(0, 0, 1); // z is up here, not three's y
  scene.add(sky);
  const sun = new THREE.DirectionalLight(0xffffff, 1.8);
  sun.position.set(2, -3, 5);
  scene.add(sun);

  // Scene: obstacles (the floor, flat and larger than 3 m, drawn light) and surfaces.
  const sceneGroup = new THREE.Group();
  for (const o of data.obstacles) {
    const big = o.kind === 'box' && Math.max(o.size[0], o.size[1]) > 3;
    const m = new THREE.Mesh(shapeGeometry(o), new THREE.MeshStandardMaterial({
      color: big ? COLORS.floor : COLORS.obstacle, roughness: 0.9 }));
    setPose(m, o.pose, 0);
    m.name = 'obstacle:' + o.name;
    sceneGroup.add(m);
  }
  for (const s of data.surfaces) {
    const pts = s.outline.map((p) => new THREE.Vector3(p[0], p[1], p[2] + 0.001));
    sceneGroup.add(new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts),
      new THREE.LineBasicMaterial({ color: COLORS.surface })));
  }
  scene.add(sceneGroup);

  // Robot: one mesh per collision shape, posed from the data each frame.
  const robot = new THREE.Group();
  // Slightly see-through, so the contacts and forces under the soles show.
  const robotMaterial = new THREE.MeshStandardMaterial({
    color: COLORS.robot, roughness: 0.6, metalness: 0.1, transparent: true, opacity: 0.6 });
  const meshes = data.robot.shapes.map((s) => {
    const m = new THREE.Mesh(shapeGeometry(s), robotMaterial);
    m.name = s.link + '/' + s.name;
    robot.add(m);
    return m;
  });
  state.robotMeshes = meshes.length;
  scene.add(robot);

  // What changes with the posture: contacts, forces, CoM.
  let overlay = new THREE.Group();
  scene.add(overlay);
  const showForces = document.getElementById('show-forces');
  const showScene = document.getElementById('show-scene');

  function showPosture(p) {
    meshes.forEach((m, i) => setPose(m, p.poses, i));
    scene.remove(overlay);
    overlay = new THREE.Group();
    const drawn = { contacts: 0, supporting: 0, geometric: 0, arrows: 0, com: 0 };
    for (const c of p.contacts) {
      const color = c.supporting ? COLORS.supporting : COLORS.geometric;
      overlay.add(polygonObject(c.outline, color, c.supporting ? 0.55 : 0.4));
      drawn.contacts++;
      c.supporting ? drawn.supporting++ : drawn.geometric++;
      if (!showForces.checked) continue;
      c.forces.forEach((f, i) => {
        const fv = v3(f);
        const len = fv.length() * FORCE_SCALE;
        if (len < 0.005) return; // a corner carrying (almost) nothing
        const arrow = new THREE.ArrowHelper(fv.normalize(), v3(c.points[i]), len, COLORS.force, 0.05, 0.03);
        // Drawn over the robot: a force acts at the sole, inside the foot's shape.
        arrow.traverse((o) => { if (o.material) { o.material.depthTest = false; o.renderOrder = 3; } });
        overlay.add(arrow);
        drawn.arrows++;
      });
    }
    // CoM: a ball, and its vertical down to the floor (z = 0), where balance is read.
    const com = v3(p.com);
    const ball = new THREE.Mesh(new THREE.SphereGeometry(0.03, 20, 14), new THREE.MeshBasicMaterial({ color: COLORS.com }));
    ball.position.copy(com);
    ball.renderOrder = 2;
    ball.material.depthTest = false; // visible through the trunk
    overlay.add(ball);
    overlay.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints([com, new THREE.Vector3(com.x, com.y, 0.002)]),
      new THREE.LineDashedMaterial({ color: COLORS.com, dashSize: 0.03, gapSize: 0.02 })).computeLineDistances());
    const foot = new THREE.Mesh(new THREE.CircleGeometry(0.02, 20), new THREE.MeshBasicMaterial({ color: COLORS.com }));
    foot.position.set(com.x, com.y, 0.002);
    overlay.add(foot);
    drawn.com = 1;
    scene.add(overlay);
    state.drawn = drawn;
  }

  // Camera: framed on every pose the robot takes (and the nearby obstacles).
  const box = new THREE.Box3();
  for (const p of data.stances.concat(data.frames))
    for (let i = 0; i < p.poses.length; i += 7) box.expandByPoint(new THREE.Vector3(p.poses[i], p.poses[i + 1], p.poses[i + 2]));
  for (const o of data.obstacles) {
    const big = o.kind === 'box' && Math.max(o.size[0], o.size[1]) > 3;
    if (!big) box.expandByPoint(new THREE.Vector3(o.pose[0], o.pose[1], o.pose[2]));
  }
  box.expandByPoint(new THREE.Vector3(box.min.x, box.min.y, 0));
  // From the robot's right, a little in front and above (x forward, z up):
  // sideways the chair, the table and a step show in profile. ?view=x,y,z
  // sets another direction (from the target towards the camera).
  const viewParam = (params.get('view') || '').split(',').map(Number);
  const viewDir = (viewParam.length === 3 && viewParam.every(Number.isFinite) && viewParam.some((v) => v !== 0)
    ? new THREE.Vector3(viewParam[0], viewParam[1], viewParam[2]) : new THREE.Vector3(0.1, -1.0, 0.4)).normalize();
  // A camera along viewDir that fits a box: its vertical extent against the
  // vertical field of view, its horizontal extent against the horizontal one.
  function makeCamera(aspect, b) {
    const fov = 35;
    const cam = new THREE.PerspectiveCamera(fov, aspect, 0.02, 50);
    cam.up.set(0, 0, 1);
    const size = b.getSize(new THREE.Vector3()), target = b.getCenter(new THREE.Vector3());
    const tv = Math.tan(THREE.MathUtils.degToRad(fov) / 2), th = tv * aspect;
    const width = Math.hypot(size.x, size.y), height = size.z + 0.15 * width;
    const dist = 1.1 * Math.max(height / 2 / tv, width / 2 / th) + width / 2;
    cam.position.copy(target).addScaledVector(viewDir, dist);
    cam.lookAt(target);
    return cam;
  }
  const camera = makeCamera(container.clientWidth / container.clientHeight, box);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(box.getCenter(new THREE.Vector3()));
  controls.update();

  // Strip mode: chosen stances side by side, one viewport each.
  const strip = (params.get('strip') || '').split(',').filter((s) => s !== '').map(Number);
  for (const i of strip)
    if (!(Number.isInteger(i) && i >= 0 && i < data.stances.length))
      return fail('strip: ' + params.get('strip') + ': stance indices 0..' + (data.stances.length - 1) + ' expected');
  const captions = [];

  function render() {
    const w = container.clientWidth, h = container.clientHeight;
    if (state.mode === 'strip') {
      const n = strip.length, cw = Math.floor(w / n);
      renderer.setScissorTest(true);
      strip.forEach((si, k) => {
        const s = data.stances[si];
        showPosture(s);
        // Each panel centred on its own stance's robot.
        const b = new THREE.Box3();
        for (let i = 0; i < s.poses.length; i += 7) b.expandByPoint(new THREE.Vector3(s.poses[i], s.poses[i + 1], s.poses[i + 2]));
        b.expandByPoint(new THREE.Vector3(b.min.x, b.min.y, 0));
        const cam = makeCamera(cw / h, b);
        renderer.setViewport(k * cw, 0, cw, h);
        renderer.setScissor(k * cw, 0, cw, h);
        renderer.render(scene, cam);
      });
      renderer.setScissorTest(false);
    } else {
      renderer.setViewport(0, 0, w, h);
      renderer.render(scene, camera);
    }
    state.renders++;
  }

  const timeline = document.getElementById('timeline');
  const label = document.getElementById('label');
  const info = document.getElementById('info');
  timeline.max = String(Math.max(0, data.frames.length - 1));
  timeline.disabled = data.frames.length === 0;
  document.getElementById('play').disabled = data.frames.length === 0;

  function describe(p, title) {
    const st = p.stance >= 0 ? data.stances[p.stance] : null;
    const check = p.feasible
      ? '<span class="ok">balanced</span>, friction margin ' + p.margin.toFixed(1) + ' N, worst torque ' +
        (100 * p.worst_torque_ratio).toFixed(0) + '% of its limit'
      : '<span class="bad">no quasi-static balance found</span>';
    const valid = st && state.mode === 'stance'
      ? (st.valid ? ' &middot; <span class="ok">valid (contract)</span>' : ' &middot; <span class="bad">NOT valid (contract)</span>')
      : '';
    info.innerHTML = '<b>' + data.scenario.name + '</b> &middot; ' + title + valid + '<br>' +
      p.contacts.map((c) => '<span class="sw" style="background:' + (c.supporting ? '#27ae60' : '#f39c12') + '"></span>' +
        c.spot + '@' + c.surface).join(' ') + '<br>' + check;
  }

  function setStance(i) {
    i = Math.max(0, Math.min(data.stances.length - 1, Math.round(i)));
    state.mode = 'stance';
    const p = data.stances[i];
    showPosture(p);
    state.current = { mode: 'stance', index: i, stance: i, t: null };
    const title = 'stance ' + (i + 1) + ' of ' + data.stances.length +
      (p.forces_from === 'plan' ? ' (plan forces)' : ' (forces: independent check)');
    label.textContent = title;
    describe(p, title);
    // The timeline follows: the first frame of this stance's phases.
    const f = data.frames.findIndex((fr) => fr.stance === i);
    if (f >= 0) timeline.value = String(f);
    render();
    return state.current;
  }

  function setFrame(i) {
    if (data.frames.length === 0) throw new Error('no trajectory in this page (acyclic-view --trajectory)');
    i = Math.max(0, Math.min(data.frames.length - 1, Math.round(i)));
    state.mode = 'frame';
    const p = data.frames[i];
    showPosture(p);
    state.current = { mode: 'frame', index: i, stance: p.stance, t: p.t };
    timeline.value = String(i);
    const title = 't = ' + p.t.toFixed(2) + ' s of ' + data.frames[data.frames.length - 1].t.toFixed(2) +
      ' s, phase ' + p.phase + (p.stance >= 0 ? ' (stance ' + (p.stance + 1) + ')' : '') + ' (forces: independent check)';
    label.textContent = title;
    describe(p, title);
    render();
    return state.current;
  }

  // The frame shown at time t: the last one at or before it.
  function setTime(t) {
    let i = 0;
    while (i + 1 < data.frames.length && data.frames[i + 1].t <= t + 1e-9) ++i;
    return setFrame(i);
  }

  // What stance i changes from the one before (the paper's figure 5 captions);
  // the first stance lists its contacts.
  function stanceChange(i) {
    const key = (c) => c.spot + '@' + c.surface;
    const cur = data.stances[i].contacts;
    if (i === 0) return cur.map((c) => c.spot + (c.supporting ? '' : ' (touching)')).join(', ');
    const prev = new Map(data.stances[i - 1].contacts.map((c) => [key(c), c]));
    const now = new Map(cur.map((c) => [key(c), c]));
    const out = [];
    for (const c of cur) {
      const p = prev.get(key(c));
      if (!p) out.push('+' + key(c) + (c.supporting ? '' : ' (touching)'));
      else if (p.supporting !== c.supporting) out.push(c.spot + (c.supporting ? ' supports' : ' stops supporting'));
    }
    for (const c of data.stances[i - 1].contacts) if (!now.has(key(c))) out.push('-' + c.spot);
    return out.join(', ') || 'no change';
  }

  let playStart = 0, playFrom = 0;
  function tick() {
    if (!state.playing) return;
    // performance.now(), not the frame's timestamp: that one can be earlier
    // than play() itself, and the timeline would stand still at its start.
    const t = playFrom + Math.max(0, performance.now() - playStart) / 1000;
    const end = data.frames[data.frames.length - 1].t;
    setTime(Math.min(t, end));
    if (t >= end) return pause();
    requestAnimationFrame(tick);
  }
  function play() {
    if (data.frames.length === 0 || state.playing) return;
    state.playing = true;
    const cur = state.mode === 'frame' ? data.frames[state.current.index].t : data.frames[Number(timeline.value)].t;
    playFrom = cur >= data.frames[data.frames.length - 1].t ? 0 : cur;
    playStart = performance.now();
    document.getElementById('play').innerHTML = '&#10074;&#10074; pause';
    requestAnimationFrame(tick);
  }
  function pause() {
    state.playing = false;
    document.getElementById('play').innerHTML = '&#9654; play';
  }

  const stanceStep = (d) => {
    pause();
    const cur = state.current ? state.current.stance : 0;
    // From a frame, "next" goes to the stance after the frame's phase start.
    setStance(state.mode === 'frame' && d < 0 ? cur : cur + d);
  };
  document.getElementById('prev').onclick = () => stanceStep(-1);
  document.getElementById('next').onclick = () => stanceStep(1);
  document.getElementById('play').onclick = () => (state.playing ? pause() : play());
  timeline.oninput = () => { pause(); setFrame(Number(timeline.value)); };
  showForces.onchange = () => (state.mode === 'stance' ? setStance(state.current.index) : setFrame(state.current.index));
  showScene.onchange = () => { sceneGroup.visible = showScene.checked; render(); };
  controls.addEventListener('change', () => { if (state.mode !== 'strip') render(); });
  window.addEventListener('keydown', (e) => {
    if (e.key === 'PageDown') stanceStep(1);
    else if (e.key === 'PageUp') stanceStep(-1);
    else if (e.key === ' ') { e.preventDefault(); state.playing ? pause() : play(); }
    else if (e.key === 'ArrowRight' && data.frames.length) setFrame((state.mode === 'frame' ? state.current.index : Number(timeline.value)) + 1);
    else if (e.key === 'ArrowLeft' && data.frames.length) setFrame((state.mode === 'frame' ? state.current.index : Number(timeline.value)) - 1);
  });
  window.addEventListener('resize', () => {
    renderer.setSize(container.clientWidth, container.clientHeight);
    camera.aspect = container.clientWidth / container.clientHeight;
    camera.updateProjectionMatrix();
    if (state.mode === 'strip') render(); else (state.mode === 'stance' ? setStance(state.current.index) : setFrame(state.current.index));
  });

  Object.assign(state, { setStance, setFrame, setTime, play, pause });

  if (strip.length) {
    state.mode = 'strip';
    state.strip = strip;
    const cw = 100 / strip.length;
    strip.forEach((si, k) => {
      const cap = document.createElement('div');
      cap.className = 'caption';
      cap.style.left = 'calc(' + (k * cw) + '% + 6px)';
      cap.textContent = 'stance ' + (si + 1) + ': ' + stanceChange(si);
      cap.style.maxWidth = 'calc(' + cw + '% - 24px)';
      document.body.appendChild(cap);
      captions.push(cap);
    });
    state.current = { mode: 'strip', index: null, stance: null, t: null };
    render();
  } else if (params.has('frame')) setFrame(Number(params.get('frame')));
  else if (params.has('t')) setTime(Number(params.get('t')));
  else setStance(Number(params.get('stance') || 0));
  state.loaded = true;
}

try {
  main();
} catch (e) {
  fail(e && e.message ? e.message : String(e));
}
