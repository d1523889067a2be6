//! What the page drives, natively on lavapipe: a fit heard, previewed, paused and cancelled
//! through an [`Observer`], its progress fraction, the fit folder it downloads, and the result
//! viewer's scene drawn by the renderer.

use crate::common;

use artmesh::data::{Dataset, JointKind, State};
use artmesh::export::{FitFolder, GLB_FILE, JOINTS_FILE, REPORT_FILE, ZIP_FILE};
use artmesh::fit::object::{FitConfig, fit_object};
use artmesh::fit::observer::{
    BakeOffView, Command, Marks, Observer, Phase, Preview, Progress, Unobserved,
};
use artmesh::fit::preset::Preset;
use artmesh::gpu::{GpuContext, GpuError};
use artmesh::render::viewer::TwinScene;
use artmesh::render::{GtRenderer, capture_dataset};
use artmesh::synth::{Category, SynthParams, generate};

fn laptop(ctx: &GpuContext, config: &FitConfig) -> Dataset {
    let object = generate(&SynthParams {
        category: Category::Laptop,
        movable_parts: Some(1),
        seed: 1005,
    })
    .unwrap();
    pollster::block_on(capture_dataset(
        ctx,
        &object,
        &config.demo_capture(1005),
        &mut |_| {},
    ))
    .unwrap()
}

/// Records everything; pauses for `pauses` checkpoints at event `pause_at`, cancels at
/// `cancel_at`.
#[derive(Default)]
struct Recorder {
    events: Vec<Progress>,
    previews: Vec<Preview>,
    pause_at: Option<usize>,
    pauses: usize,
    paused: usize,
    cancel_at: Option<usize>,
    /// Previews wanted (default 3).
    previews_wanted: Option<usize>,
    /// Whether the articulation is watched as pictures, and the bake-offs heard.
    articulation_views: bool,
    bake_offs: Vec<BakeOffView>,
}

impl Observer for Recorder {
    fn progress(&mut self, event: &Progress) {
        self.events.push(*event);
    }
    fn wants_preview(&mut self) -> bool {
        self.previews.len() < self.previews_wanted.unwrap_or(3)
    }
    fn preview(&mut self, preview: Preview) {
        self.previews.push(preview);
    }
    fn wants_articulation_views(&self) -> bool {
        self.articulation_views
    }
    fn bake_off(&mut self, view: BakeOffView) {
        self.bake_offs.push(view);
    }
    fn command(&mut self) -> Command {
        let n = self.events.len();
        if self.cancel_at == Some(n) {
            return Command::Cancel;
        }
        if self.pause_at == Some(n) && self.paused < self.pauses {
            self.paused += 1;
            return Command::Pause;
        }
        Command::Run
    }
}

#[test]
fn a_cancelled_fit_stops_at_a_checkpoint_and_a_paused_one_waits() {
    let ctx = common::context();
    let config = FitConfig::preset(Preset::Tiny);
    let dataset = laptop(&ctx, &config);
    let mut recorder = Recorder {
        pause_at: Some(2),
        pauses: 3,
        cancel_at: Some(4),
        ..Recorder::default()
    };
    let result = pollster::block_on(fit_object(&ctx, &dataset, &config, &mut recorder));
    assert!(matches!(result, Err(GpuError::Cancelled)), "{result:?}");
    assert_eq!(recorder.events.len(), 4, "no event after the cancel");
    assert_eq!(
        recorder.paused, 3,
        "the pause was asked about until it ended"
    );
    let first = &recorder.previews[0];
    assert_eq!((first.width, first.height, first.view), (32, 32, 0));
    assert_eq!(first.render.len(), 32 * 32 * 3);
    assert_eq!(first.target.len(), 32 * 32 * 3);
    assert_ne!(first.render, first.target);
    // The target is the capture's first training view, composited on black.
    assert!(first.target.iter().any(|&v| v > 0));
}

#[test]
fn a_heard_fit_reports_every_stage_in_order_and_its_folder_holds_the_downloads() {
    let ctx = common::context();
    let config = FitConfig::preset(Preset::Tiny);
    let dataset = laptop(&ctx, &config);
    // A preview at every checkpoint and the articulation in pictures, the page's worst case.
    let mut recorder = Recorder {
        previews_wanted: Some(usize::MAX),
        articulation_views: true,
        ..Recorder::default()
    };
    let fit = pollster::block_on(fit_object(&ctx, &dataset, &config, &mut recorder)).unwrap();
    let fractions: Vec<f64> = recorder
        .events
        .iter()
        .map(|e| config.fraction_done(e))
        .collect();
    assert!(
        fractions.windows(2).all(|w| w[1] >= w[0]),
        "fraction goes back: {fractions:?}"
    );
    assert_eq!(fractions[0], 0.0);
    assert_eq!(*fractions.last().unwrap(), 1.0);
    let stages: Vec<&str> = recorder.events.iter().map(|e| e.phase.stage()).collect();
    for stage in [
        "reconstruction",
        "remeshing",
        "joint measurement",
        "articulation",
        "bake-off decision",
    ] {
        assert!(stages.contains(&stage), "{stage} missing from {stages:?}");
    }
    // The measurement reports before and after each movable part (the lid): seconds of CPU each.
    let measured: Vec<(u32, u32)> = recorder
        .events
        .iter()
        .filter(|e| e.phase == Phase::Measure)
        .map(|e| (e.iteration, e.iterations))
        .collect();
    assert_eq!(measured, [(0, 1), (1, 1)]);
    let last = recorder.events.last().unwrap();
    assert_eq!((last.phase, last.state), (Phase::Done, State::End));
    assert!(
        recorder.previews.len() > 10,
        "{} previews",
        recorder.previews.len()
    );
    // The articulation in pictures: the start mesh moved by the seeds, then by the fitted joints,
    // both from an end-state view; and the lid's bake-off, its two candidates side by side.
    let moved = |by: &str| {
        let p = recorder.previews.iter().find(|p| p.moved_by == Some(by));
        p.unwrap_or_else(|| panic!("no preview moved by the {by}"))
    };
    let (seeds, fitted) = (moved("joint seeds"), moved("fitted joints"));
    assert_eq!((seeds.state, fitted.phase), (State::End, Phase::Done));
    assert_eq!(seeds.target, fitted.target, "one view, one photo");
    assert_ne!(seeds.render, fitted.render, "the seeds are not the fit");
    assert_eq!(recorder.bake_offs.len(), 1, "one bake-off per movable part");
    let b = &recorder.bake_offs[0];
    assert_eq!((b.part, b.revolute.len()), (1, b.target.len()));
    assert_ne!(
        b.revolute, b.prismatic,
        "each candidate moves the lid its own way"
    );
    let (rot, trans) = (b.revolute_loss.unwrap(), b.prismatic_loss.unwrap());
    assert!(
        rot < trans,
        "the hinge fits the lid better: {rot} vs {trans}"
    );
    assert_eq!(b.kind, fit.articulation.joints[0].kind);
    // Marked as the page draws them: the laptop's lid's pixels, its fitted axis a hinge in view,
    // each candidate's picture marked with its own kind.
    let pixels = (fitted.width * fitted.height) as usize;
    assert_eq!(fitted.marks.parts.len(), pixels);
    assert!(fitted.marks.parts.contains(&1), "the lid is labelled");
    let [axis] = fitted.marks.axes[..] else {
        panic!("one axis: {:?}", fitted.marks.axes)
    };
    assert_eq!((axis.part, axis.kind), (1, fit.articulation.joints[0].kind));
    let inside = |p: [f32; 2]| (0.0..fitted.width as f32).contains(&p[0]);
    assert!(inside(axis.from) || inside(axis.to), "{axis:?}");
    let kinds = |m: &Marks| m.axes.iter().map(|a| a.kind).collect::<Vec<_>>();
    assert_eq!(kinds(&b.revolute_marks), [JointKind::Revolute]);
    assert_eq!(kinds(&b.prismatic_marks), [JointKind::Prismatic]);
    // Watching a fit changes nothing: unwatched, the same fit gives the same meshes and joints.
    let unwatched =
        pollster::block_on(fit_object(&ctx, &dataset, &config, &mut Unobserved)).unwrap();
    for (a, b) in fit
        .reconstruction
        .states
        .iter()
        .zip(&unwatched.reconstruction.states)
    {
        assert!(
            a.field == b.field,
            "the previews changed the {:?} state's mesh",
            a.state
        );
    }
    assert_eq!(
        fit.articulation.gt_joints(),
        unwatched.articulation.gt_joints()
    );

    let folder = FitFolder::build(&fit, &dataset, &config, "laptop", "Laptop", 1.0).unwrap();
    for file in [
        GLB_FILE,
        ZIP_FILE,
        JOINTS_FILE,
        REPORT_FILE,
        "urdf/twin.urdf",
    ] {
        assert!(folder.files.contains_key(file), "{file} missing");
    }
    let report: serde_json::Value = serde_json::from_slice(&folder.files[REPORT_FILE]).unwrap();
    assert_eq!(report["id"], "laptop");
    assert!(
        report["metrics"]["axis_ang"].as_f64().unwrap() < 10.0,
        "{report}"
    );
    assert_eq!(folder.joints.len(), 1);

    // The viewer's scene of this twin: the slider moves the lid on screen.
    let mut scene = TwinScene::new(folder.twin.object(), folder.twin.end_configuration());
    let renderer = GtRenderer::new(&ctx, 64, 48).unwrap();
    let draw = |scene: &TwinScene| {
        pollster::block_on(renderer.render_view(&ctx, &scene.meshes(), &scene.camera(64, 48)))
            .unwrap()
    };
    let start = draw(&scene);
    let joint = scene.joints()[0].clone();
    assert!(scene.set_joint(0, joint.end));
    let end = draw(&scene);
    let changed = start
        .parts
        .ids
        .iter()
        .zip(&end.parts.ids)
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        changed > 20,
        "{changed} pixels changed part when the lid moved"
    );
    // The hinge axis is drawn (part id −1 over the background's −1 does not tell; its colour does).
    let orange = end
        .rgba
        .pixels
        .chunks_exact(4)
        .filter(|p| p[3] == 255 && p[0] > 150 && p[2] < 80)
        .count();
    assert!(orange > 0, "no axis rod pixels");
}
