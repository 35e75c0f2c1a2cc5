"""The balls of a 'dem' run seen from the vial: their paths as three projections, and a short animation.

The engine records the balls' centres in the lab frame (x along the vial's axis at rest, z up) and the
vial's pose (centre r_v; roll, pitch, yaw). Drawn in the lab frame, the paths would mostly show the
vial's own stroke; in the vial frame, s = Qᵀ(r − r_v) with Q = R_z(yaw)·R_y(pitch)·R_x(roll) (MODEL.md
§12.1), the walls stand still and every path can be read against them.

Matplotlib is imported inside the functions, as in :mod:`shakermill.views.figures`.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from shakermill.parameters.defaults import ANIMATION_FRAMES, MOST_ANIMATION_FRAMES
from shakermill.parameters.keys import Parameters
from shakermill.parameters.kinematic_models import KINEMATIC_MODELS
from shakermill.physics import kinematics

if TYPE_CHECKING:
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from PIL.Image import Image as PillowImage

# Neither blue nor green: the temperature figures draw the vial and the air in those.
BALL_COLOURS = ("tab:red", "tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan", "tab:gray")
# The projections of the trajectory figure: (horizontal axis, vertical axis, name), axes of the vial frame.
VIEWS = (("x", "y", "top view"), ("x", "z", "side view"), ("y", "z", "end view"))
AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
AXIS_MEANING = {"x": "along the vial's axis", "y": "across", "z": "up at rest"}
# A jar whose axis stands up (a planetary mill's): the same projections seen from the side, and from the top.
UPRIGHT_VIEW_NAMES = {"top view": "side view", "side view": "side view, a quarter turn round", "end view": "top view"}
UPRIGHT_AXIS_MEANING = {"x": "along the jar's axis, up", "y": "across", "z": "across"}


def axis_label(params: Parameters, axis: str) -> str:
    upright = KINEMATIC_MODELS[params.kinematics].axis_upright
    return f"{axis}, {(UPRIGHT_AXIS_MEANING if upright else AXIS_MEANING)[axis]} (mm)"


def view_name(params: Parameters, name: str) -> str:
    return UPRIGHT_VIEW_NAMES[name] if KINEMATIC_MODELS[params.kinematics].axis_upright else name


# A window of minutes at 10 kHz would be millions of points per ball: longer windows are drawn thinned to this.
MOST_PATH_POINTS = 20_000
ANIMATION_FPS = 24
ANIMATION_DPI = 100
ANIMATION_SIZE_INCHES = (6.4, 4.0)
# Frames of each ball's trail in the animation.
TRAIL_FRAMES = 12
GIF_COLOURS = 64
MM = 1e3


def ball_colours(n_balls: int) -> list:
    """One colour per ball, the same in every figure; past eight balls, a colour map's shades."""
    if n_balls <= len(BALL_COLOURS):
        return list(BALL_COLOURS[:n_balls])
    from matplotlib import colormaps

    return [colormaps["plasma"](value) for value in np.linspace(0.0, 0.9, n_balls)]


def vial_frame(position: np.ndarray, vial_centre: np.ndarray, vial_angles: np.ndarray) -> np.ndarray:
    """Ball centres (time, ball, axis) in the vial frame, s = Qᵀ(r − r_v), from lab-frame ``position``
    (time, ball, axis), the vial's centre (time, axis) and its roll, pitch and yaw (time, angle)."""
    rotation = np.empty((3, 3))
    local = np.empty(np.shape(position))
    for row, (roll, pitch, yaw) in enumerate(np.asarray(vial_angles, dtype=float)):
        # The engine's own Q, so that the figure and the wall contacts share one convention.
        kinematics.rotation_matrix(roll, pitch, yaw, rotation)
        # (r − r_v)·Q as rows is Qᵀ(r − r_v) as columns, for every ball at once.
        local[row] = (position[row] - vial_centre[row]) @ rotation
    return local


def window_in_vial_frame(window: xr.Dataset) -> np.ndarray:
    """The ball centres of a record window (time, ball, axis) in the vial frame, in mm."""
    position = window["position"].transpose("time", "ball", "axis").values
    centre, angles = (
        window["vial_centre"].transpose("time", "axis").values,
        window["vial_angles"].transpose("time", "angle").values,
    )
    return MM * vial_frame(position, centre, angles)


def spread_samples(samples: int, most: int) -> np.ndarray:
    """Indices of ``most`` of ``samples`` samples, evenly spread from the first to the last (all of them if fewer)."""
    return np.linspace(0, samples - 1, min(samples, most)).round().astype(np.int64)


def new_figure(size: tuple[float, float]) -> Figure:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(figure)
    return figure


def draw_vial(axis: Axes, across: str, up: str, params: Parameters) -> None:
    """The vial's inner wall in the projection (``across``, ``up``) in mm: its length and bore, or its bore as a
    circle."""
    from matplotlib.patches import Circle, Rectangle

    length, bore = params.vial_length * MM, params.vial_diameter * MM
    wall = Rectangle((-length / 2, -bore / 2), length, bore) if across == "x" else Circle((0.0, 0.0), bore / 2)
    wall.set_fill(False)
    wall.set_edgecolor("0.2")
    wall.set_linewidth(1.2)
    wall.set_label("vial, inner wall")
    axis.add_patch(wall)
    # Room for the wall's line and the balls touching it.
    reach = (length if across == "x" else bore) / 2 * 1.04, bore / 2 * 1.04
    axis.set_xlim(-reach[0], reach[0])
    axis.set_ylim(-reach[1], reach[1])
    axis.set_aspect("equal")
    axis.set_xlabel(axis_label(params, across))
    axis.set_ylabel(axis_label(params, up))


def trajectory_figure(
    params: Parameters, window: xr.Dataset, record_window: tuple[float, float] | None = None
) -> Figure:
    """Each ball's centre over ``window`` in the vial frame (mm): top, side and end view, the vial's inner
    wall, and each ball to scale where the window ends.

    ``record_window`` (start, length) in s names the time span; without it the stored points do.
    """
    from matplotlib.patches import Circle

    local = window_in_vial_frame(window)
    time = window["time"].values
    start, end = (record_window[0], sum(record_window)) if record_window else (time[0], time[-1])
    drawn = spread_samples(time.size, MOST_PATH_POINTS)
    radii = np.asarray(params.ball_values("ball_radius")) * MM
    colours = ball_colours(radii.size)
    length, bore = params.vial_length * MM, params.vial_diameter * MM
    figure = new_figure((12.0, 3.9))
    axes = figure.subplots(1, 3, width_ratios=(length, length, bore))
    for axis, (across, up, name) in zip(axes, VIEWS):
        draw_vial(axis, across, up, params)
        i, j = AXIS_INDEX[across], AXIS_INDEX[up]
        for ball, colour in enumerate(colours):
            axis.plot(local[drawn, ball, i], local[drawn, ball, j], color=colour, lw=0.6, label=f"ball {ball}")
            where = (local[-1, ball, i], local[-1, ball, j])
            axis.add_patch(Circle(where, radii[ball], facecolor=colour, edgecolor="black", lw=0.5, alpha=0.4))
        axis.set_title(view_name(params, name))
        axis.grid(alpha=0.3)
    thinned = "" if drawn.size == time.size else f" ({drawn.size} of {time.size} stored points)"
    figure.suptitle(
        f"Ball centres in the vial frame, t = {start:g}–{end:g} s{thinned}; "
        f"discs: the balls to scale at t = {time[-1]:.4g} s"
    )
    handles, labels = axes[0].get_legend_handles_labels()
    figure.legend(handles, labels, loc="outside lower center", ncols=min(len(labels), 8), fontsize="small")
    return figure


def animation_gif(
    params: Parameters,
    window: xr.Dataset,
    *,
    frames: int = ANIMATION_FRAMES,
    fps: int = ANIMATION_FPS,
    dpi: int = ANIMATION_DPI,
) -> bytes:
    """A GIF of the balls (discs of their radius, with a trail of the last frames) in the side view of the vial frame
    over ``window``: ``frames`` frames (1 to :data:`MOST_ANIMATION_FRAMES`; fewer if the window holds fewer
    samples) at ``fps``, ``dpi`` pixels per inch.

    Matplotlib's FuncAnimation with PillowWriter redraws the whole figure two or three times a frame (18 s
    for 120 frames); here the still parts are drawn once and only the balls onto them (2 s), and the GIF is
    built in memory, for the caller to write atomically.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.patches import Circle

    local = window_in_vial_frame(window)
    time = window["time"].values
    shown = spread_samples(time.size, min(max(frames, 1), MOST_ANIMATION_FRAMES))
    radii = np.asarray(params.ball_values("ball_radius")) * MM
    figure = new_figure(ANIMATION_SIZE_INCHES)
    figure.set_dpi(dpi)
    axis = figure.subplots()
    draw_vial(axis, "x", "z", params)
    axis.set_title(f"Balls in the vial frame, {view_name(params, 'side view')}", loc="left")
    # Animated artists are left out of the full draw: it makes the still background they are drawn onto.
    discs = [
        Circle((0.0, 0.0), radius, facecolor=colour, edgecolor="black", lw=0.5, animated=True)
        for radius, colour in zip(radii, ball_colours(radii.size))
    ]
    for disc in discs:
        axis.add_patch(disc)
    # Opaque: the GIF's palette holds the balls' colours, not their blends with the background.
    trails = [axis.plot([], [], color=colour, lw=0.8, animated=True)[0] for colour in ball_colours(radii.size)]
    clock = axis.text(1.0, 1.01, "", transform=axis.transAxes, ha="right", va="bottom", animated=True)
    canvas = figure.canvas
    if not isinstance(canvas, FigureCanvasAgg):  # new_figure's: the frames are copied from its pixels
        raise TypeError(f"animation_gif draws on Agg's canvas, not on {type(canvas).__name__}")
    canvas.draw()
    background = canvas.copy_from_bbox(figure.bbox)
    images = []
    for frame, now in enumerate(shown):
        trail = shown[max(0, frame - TRAIL_FRAMES) : frame + 1]
        for ball, (disc, line) in enumerate(zip(discs, trails)):
            disc.center = local[now, ball, 0], local[now, ball, 2]
            line.set_data(local[trail, ball, 0], local[trail, ball, 2])
        clock.set_text(f"t = {time[now]:.4f} s")
        canvas.restore_region(background)
        for artist in (*trails, *discs, clock):
            axis.draw_artist(artist)
        images.append(_frame_image(canvas))
    return gif_bytes(images, fps)


def _frame_image(canvas: FigureCanvasAgg) -> PillowImage:
    """What ``canvas`` shows now, as an RGB image of its own (the canvas's buffer is drawn over next frame)."""
    from PIL import Image

    size = canvas.get_width_height()
    return Image.frombuffer("RGBA", size, canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")


def gif_bytes(images: Sequence[PillowImage], fps: int) -> bytes:
    """``images`` as a looping GIF at ``fps`` frames per second, in memory.

    One palette for all frames, from the first (every ball is in it): Pillow's own choice per frame
    takes six times longer, and the figure has few colours.
    """
    from PIL import Image

    palette = images[0].quantize(colors=GIF_COLOURS, method=Image.Quantize.FASTOCTREE)
    frames = [image.quantize(palette=palette, dither=Image.Dither.NONE) for image in images]
    buffer = io.BytesIO()
    frames[0].save(buffer, format="GIF", save_all=True, append_images=frames[1:], duration=round(1000 / fps), loop=0)
    return buffer.getvalue()
