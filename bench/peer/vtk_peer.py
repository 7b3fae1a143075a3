# vtk_peer.py - hybriddiff's projection frame against VTK's volume ray casters on the head CT,
# interleaved in one run (make bench-peer; run by pvpython under xvfb-run).
#
# Starts build/hdpeer (which converges hybriddiff's light once, CPU backend) and drives it over a
# pipe, so that each round times, one after the other at each size:
#   hd       hybriddiff: one hd_render per orbit frame over the converged light (projection only);
#            --hd NAME=EXE (repeatable) drives other builds of hdpeer instead, each an engine of
#            its own, e.g. --hd cpu=build/hdpeer --hd gl=build/hdpeer_gl (hdpeer_opencl,
#            hdpeer_vulkan, hdpeer_old: mk/bench.mk)
#   vtk-fp   vtkFixedPointVolumeRayCastMapper (CPU), emission-absorption, unshaded
#   vtk-gpu  vtkGPUVolumeRayCastMapper (OpenGL, here Mesa llvmpipe), emission-absorption, unshaded
#   vtk-gi   vtkGPUVolumeRayCastMapper's volumetric scattering (VTK's global illumination:
#            shading on, SetVolumetricScatteringBlending(2), the key light as a scene light)
# The VTK scene mirrors hdpeer's: the TF table hdpeer uses (colour and opacity per entry, opacity
# per ScalarOpacityUnitDistance converted from hybriddiff's sigma_t = alpha * extinction), the
# world box (largest side 1, centred at 0), the camera, and the sample distance (hybriddiff's step).
# Every frame of a timed run moves the camera along the orbit (azimuth 360 i / N).
#
# Usage: pvpython vtk_peer.py [--hdpeer build/hdpeer | --hd NAME=EXE ...] [--data data/head.nrrd] [--sizes 512,1024]
#          [--frames 3] [--gi-frames 2] [--rounds 2] [--pictures docs/peer|none]
# (pvpython cannot take an empty argument: --pictures none, not --pictures '')
import argparse
import math
import os
import statistics
import subprocess
import sys
import time

import vtkmodules.all as vtk

EYE0 = (0.6, 1.65, 0.3)
# CPU time is reported over the online cores: the wall time on otherwise idle cores, for engines
# whose threads block rather than spin (hybriddiff's CPU backend, VTK's fixed-point mapper and
# llvmpipe do), so it stays put on a loaded machine while the wall clock stretches.
CORES = os.cpu_count() or 1
TARGET = (0.0, 0.0, -0.04)
FOV = 37.0


def orbit_eye(deg):
    a = math.radians(deg)
    dx, dy = EYE0[0] - TARGET[0], EYE0[1] - TARGET[1]
    return (TARGET[0] + math.cos(a) * dx - math.sin(a) * dy,
            TARGET[1] + math.sin(a) * dx + math.cos(a) * dy, EYE0[2])


def key_light_from(eye):
    """hdrender's key light (bench/hd_orbit_scene.h): the direction it comes from, unit."""
    w = [TARGET[k] - eye[k] for k in range(3)]
    n = math.sqrt(sum(x * x for x in w)); w = [x / n for x in w]
    up = (0.0, 0.0, 1.0)
    u = [w[1] * up[2] - w[2] * up[1], w[2] * up[0] - w[0] * up[2], w[0] * up[1] - w[1] * up[0]]
    n = math.sqrt(sum(x * x for x in u)); u = [x / n for x in u]
    v = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    f = [-0.55 * u[k] + 0.65 * v[k] - 0.75 * w[k] for k in range(3)]
    n = math.sqrt(sum(x * x for x in f))
    return [x / n for x in f]


class HdPeer:
    def __init__(self, exe, data):
        self.p = subprocess.Popen([exe, data], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, bufsize=1)

    def ask(self, line):
        self.p.stdin.write(line + "\n")
        self.p.stdin.flush()
        ans = self.p.stdout.readline()
        if not ans:
            sys.exit("vtk_peer: hdpeer ended (see its messages above)")
        return ans.split()

    def tf(self):
        h = self.ask("tf")
        lo, hi, count, ext, step = float(h[1]), float(h[2]), int(h[3]), float(h[4]), float(h[5])
        side = [float(x) for x in h[6:9]]
        dims = [int(x) for x in h[9:12]]
        table = [[float(x) for x in self.p.stdout.readline().split()] for _ in range(count)]
        return lo, hi, ext, step, side, dims, table

    def quit(self):
        self.p.stdin.write("quit\n")
        self.p.stdin.close()
        self.p.wait()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--hdpeer", default="build/hdpeer")
    ap.add_argument("--hd", action="append", default=[], metavar="NAME=EXE",
                    help="a hybriddiff engine (repeatable; default hd=HDPEER)")
    ap.add_argument("--data", default="data/head.nrrd")
    ap.add_argument("--sizes", default="512,1024")
    ap.add_argument("--frames", type=int, default=3, help="orbit frames per engine and round")
    ap.add_argument("--gi-frames", type=int, default=2, help="frames of vtk-gi (slow)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--pictures", default="docs/peer", help="directory, or 'none'")
    a = ap.parse_args()
    sizes = [int(s) for s in a.sizes.split(",") if s]

    hd_specs = [x.split("=", 1) for x in a.hd] if a.hd else [["hd", a.hdpeer]]
    if any(len(x) != 2 or not x[0] or x[0].startswith("vtk") for x in hd_specs):
        sys.exit("vtk_peer: --hd takes NAME=EXE, NAME not starting with vtk")
    hds = {name: HdPeer(exe, a.data) for name, exe in hd_specs}
    hd_names = [name for name, _ in hd_specs]
    hd = hds[hd_names[0]]
    lo, hi, ext, step, side, dims, table = hd.tf()
    for name in hd_names[1:]:
        if hds[name].tf()[:6] != (lo, hi, ext, step, side, dims):
            sys.exit("vtk_peer: %s's scene differs from %s's" % (name, hd_names[0]))

    # the volume, in hybriddiff's world box: voxel centres at ((i + 0.5) / n - 0.5) * side
    reader = vtk.vtkNrrdReader()
    reader.SetFileName(a.data)
    reader.Update()
    img = reader.GetOutput()
    if list(img.GetDimensions()) != dims:
        sys.exit("vtk_peer: VTK reads %s, hdpeer %s" % (img.GetDimensions(), dims))
    info = vtk.vtkImageChangeInformation()
    info.SetInputConnection(reader.GetOutputPort())
    sp = [side[k] / dims[k] for k in range(3)]
    info.SetOutputSpacing(*sp)
    info.SetOutputOrigin(*[-side[k] / 2 + sp[k] / 2 for k in range(3)])
    info.Update()

    # TF: entry i at lo + (hi - lo) i / (count - 1); values outside [lo, hi] clamp to the ends
    unit = min(sp)
    ctf = vtk.vtkColorTransferFunction()
    otf = vtk.vtkPiecewiseFunction()
    n = len(table)
    for i, (r, g, b, al) in enumerate(table):
        x = lo + (hi - lo) * i / (n - 1)
        ctf.AddRGBPoint(x, r, g, b)
        otf.AddPoint(x, 1.0 - math.exp(-al * ext * unit))
    ctf.SetClamping(1)
    otf.SetClamping(1)

    def make_prop(shade):
        p = vtk.vtkVolumeProperty()
        p.SetColor(ctf)
        p.SetScalarOpacity(otf)
        p.SetScalarOpacityUnitDistance(unit)
        p.SetInterpolationTypeToLinear()
        if shade:
            p.ShadeOn()
            p.SetAmbient(0.1)
            p.SetDiffuse(0.9)
            p.SetSpecular(0.0)
        else:
            p.ShadeOff()
        return p

    fp = vtk.vtkFixedPointVolumeRayCastMapper()
    fp.SetSampleDistance(step)
    fp.SetInteractiveSampleDistance(step)
    fp.SetImageSampleDistance(1.0)
    fp.SetMinimumImageSampleDistance(1.0)
    fp.SetMaximumImageSampleDistance(1.0)
    fp.SetAutoAdjustSampleDistances(0)
    gpu = vtk.vtkGPUVolumeRayCastMapper()
    gi = vtk.vtkGPUVolumeRayCastMapper()
    for m in (gpu, gi):
        m.SetAutoAdjustSampleDistances(0)
        m.SetLockSampleDistanceToInputSpacing(0)
        m.SetSampleDistance(step)
    gi.SetVolumetricScatteringBlending(2.0)
    for m in (fp, gpu, gi):
        m.SetInputConnection(info.GetOutputPort())

    win = vtk.vtkRenderWindow()
    win.SetMultiSamples(0)
    engines = {}
    for name, mapper, shade in (("vtk-fp", fp, False), ("vtk-gpu", gpu, False), ("vtk-gi", gi, True)):
        vol = vtk.vtkVolume()
        vol.SetMapper(mapper)
        vol.SetProperty(make_prop(shade))
        ren = vtk.vtkRenderer()
        ren.SetBackground(0, 0, 0)
        ren.AddVolume(vol)
        ren.AutomaticLightCreationOff()
        ren.RemoveAllLights()
        light = vtk.vtkLight()
        light.SetLightTypeToSceneLight()
        light.SetPositional(0)
        engines[name] = (ren, light)
    vtk_names = ["vtk-fp", "vtk-gpu", "vtk-gi"]
    names = hd_names + vtk_names

    def use(name, size, deg):
        ren, light = engines[name]
        if win.GetRenderers().GetNumberOfItems() != 1 or win.GetRenderers().GetFirstRenderer() is not ren:
            win.GetRenderers().RemoveAllItems()
            win.AddRenderer(ren)
        if tuple(win.GetSize()) != (size, size):
            win.SetSize(size, size)
        cam = ren.GetActiveCamera()
        eye = orbit_eye(deg)
        cam.SetPosition(*eye)
        cam.SetFocalPoint(*TARGET)
        cam.SetViewUp(0, 0, 1)
        cam.SetViewAngle(FOV)
        ren.ResetCameraClippingRange()
        f = key_light_from(orbit_eye(0.0))
        light.SetFocalPoint(*TARGET)
        light.SetPosition(*[TARGET[k] + 10 * f[k] for k in range(3)])
        ren.RemoveAllLights()
        ren.AddLight(light)

    def time_vtk(name, size, frames):
        use(name, size, 0.0)
        win.Render()  # warm-up: textures, shaders, buffers at this size
        win.WaitForCompletion()
        t0, c0 = time.perf_counter(), time.process_time()
        for i in range(frames):
            use(name, size, 360.0 * i / frames)
            win.Render()
        win.WaitForCompletion()
        return (1e3 * (time.perf_counter() - t0) / frames,
                1e3 * (time.process_time() - c0) / frames / CORES)

    use("vtk-gpu", sizes[0], 0.0)
    win.Render()
    gl = [l for l in win.ReportCapabilities().splitlines() if "renderer string" in l]
    print("bench-peer: VTK %s (%s), hybriddiff via %s; %d rounds, %d frames "
          "per engine (vtk-gi %d), interleaved" % (vtk.vtkVersion.GetVTKVersion(),
          gl[0].split(":", 1)[1].strip() if gl else "OpenGL renderer unknown",
          ", ".join("%s=%s" % (n, e) for n, e in hd_specs), a.rounds, a.frames, a.gi_frames), flush=True)
    ms = {(s, e): [] for s in sizes for e in names}
    cms = {(s, e): [] for s in sizes for e in names}
    for r in range(a.rounds):
        for s in sizes:
            for e in names:
                if e in hds:
                    ans = hds[e].ask("frames %d %d" % (s, a.frames))
                    t, c = float(ans[1]), float(ans[3]) / CORES
                    if float(ans[2]) != 0.0:
                        print("bench-peer: %s spent %s s on light during timed frames" % (e, ans[2]))
                else:
                    t, c = time_vtk(e, s, a.gi_frames if e == "vtk-gi" else a.frames)
                ms[(s, e)].append(t)
                cms[(s, e)].append(c)
                print("round %d %4d^2 %-8s %9.1f ms/frame wall %9.1f ms/frame CPU/%d" % (
                    r + 1, s, e, t, c, CORES), flush=True)
    for title, tab in (("wall clock", ms), ("process CPU time / %d cores" % CORES, cms)):
        print("\nms per orbit frame, %s (median of %d rounds; same run, interleaved):" % (title, a.rounds))
        print("%6s" % "size" + "".join(" %10s" % e for e in names) +
              "".join("  %s/vtk-fp  %s/vtk-gpu" % (h, h) for h in hd_names))
        for s in sizes:
            med = {e: statistics.median(tab[(s, e)]) for e in names}
            print("%4d^2" % s + "".join(" %10.1f" % med[e] for e in names) +
                  "".join("  %*.2f  %*.2f" % (len(h) + 7, med[h] / med["vtk-fp"], len(h) + 8,
                                               med[h] / med["vtk-gpu"]) for h in hd_names))

    if a.pictures and a.pictures != "none":
        os.makedirs(a.pictures, exist_ok=True)
        for s in sizes[:1]:
            files = []
            p = os.path.abspath(os.path.join(a.pictures, "hd-%d.png" % s))
            hd.ask("picture %d %s" % (s, p))
            files.append(p)
            for e in vtk_names:
                use(e, s, 0.0)
                win.Render()
                grab = vtk.vtkWindowToImageFilter()
                grab.SetInput(win)
                grab.ReadFrontBufferOff()
                grab.Update()
                p = os.path.join(a.pictures, "%s-%d.png" % (e, s))
                w = vtk.vtkPNGWriter()
                w.SetFileName(p)
                w.SetInputConnection(grab.GetOutputPort())
                w.Write()
                files.append(p)
            app = vtk.vtkImageAppend()
            app.SetAppendAxis(0)
            for p in files:
                rd = vtk.vtkPNGReader()
                rd.SetFileName(p)
                rgb = vtk.vtkImageExtractComponents()
                rgb.SetInputConnection(rd.GetOutputPort())
                rgb.SetComponents(0, 1, 2)
                app.AddInputConnection(rgb.GetOutputPort())
            w = vtk.vtkPNGWriter()
            out = os.path.join(a.pictures, "side-by-side-%d.png" % s)
            w.SetFileName(out)
            w.SetInputConnection(app.GetOutputPort())
            w.Write()
            for p in files:
                os.remove(p)
            print("picture: %s (left to right: %s)" % (out, ", ".join([hd_names[0]] + vtk_names)))
    for h in hds.values():
        h.quit()


main()
