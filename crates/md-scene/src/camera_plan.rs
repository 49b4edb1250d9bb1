//! The camera of every frame of a render: the first frame's camera moved along an orbit or
//! keyframes ([`MotionSpec`]), and translated by the move of a followed selection's centre.
//!
//! A frame's camera depends only on its position `k` in the render and its own atoms, so the
//! parts of a render split across processes draw exactly what one process would.

use std::fmt;

use glam::Vec3;
use texmap_core::camera::{Camera, CameraError};
use texmap_core::camera_path::{KeyframeError, Keyframes, Pose};
use texmap_md_io::{Frame, Selection, SelectionError};

use crate::centre_of;

/// How the camera moves over the frames of a render.
#[derive(Clone, Debug)]
pub enum MotionSpec {
    /// The first frame's camera throughout.
    Still,
    /// An orbit about the target, this many degrees per rendered frame.
    Orbit {
        /// Degrees per frame.
        degrees_per_frame: f32,
    },
    /// An orbit of this many full turns over the whole render.
    OrbitTurns {
        /// Turns over the render.
        turns: f32,
    },
    /// The text of a keyframes file ([`Keyframes::parse`]), relative to the first camera.
    Keyframes(String),
}

/// Why a [`CameraPlan`] was refused or a frame's camera could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraPlanError {
    /// [`MotionSpec::Orbit`] with a degree count that is not finite.
    OrbitNotFinite {
        /// The refused degrees per frame.
        degrees: f32,
    },
    /// [`MotionSpec::OrbitTurns`] with a turn count that is not finite.
    OrbitTurnsNotFinite {
        /// The refused turns.
        turns: f32,
    },
    /// The keyframes text did not parse.
    Keyframes(KeyframeError),
    /// The followed selection could not be evaluated.
    Follow(SelectionError),
    /// The followed selection (its text) selects no atom of the first frame.
    FollowNoneFirst {
        /// The selection's text.
        selection: String,
    },
    /// The followed selection (its text) selects no atom of a later frame.
    FollowNone {
        /// The selection's text.
        selection: String,
    },
    /// The camera of rendered frame `frame` could not be made.
    Camera {
        /// The frame's position in the render.
        frame: usize,
        /// Why.
        error: CameraError,
    },
}

impl fmt::Display for CameraPlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CameraPlanError::OrbitNotFinite { degrees } => {
                write!(f, "orbit {degrees}: must be a finite number of degrees")
            }
            CameraPlanError::OrbitTurnsNotFinite { turns } => {
                write!(f, "orbit turns {turns}: must be a finite number")
            }
            CameraPlanError::Keyframes(e) => write!(f, "keyframes: {e}"),
            CameraPlanError::Follow(e) => write!(f, "followed selection: {e}"),
            CameraPlanError::FollowNoneFirst { selection } => write!(
                f,
                "followed selection {selection:?} selects none of the first frame's atoms"
            ),
            CameraPlanError::FollowNone { selection } => write!(
                f,
                "followed selection {selection:?} selects none of this frame's atoms"
            ),
            CameraPlanError::Camera { frame, error } => {
                write!(f, "camera of rendered frame {frame}: {error}")
            }
        }
    }
}

impl std::error::Error for CameraPlanError {}

#[derive(Clone, Debug)]
enum Motion {
    Still,
    Orbit { degrees_per_frame: f32 },
    Keys(Keyframes),
}

/// The camera of every frame of a render (see the module docs).
#[derive(Clone, Debug)]
pub struct CameraPlan {
    template: Camera,
    pose: Pose,
    motion: Motion,
    /// The followed selection and its atoms' centre in the first frame.
    follow: Option<(Selection, Vec3)>,
}

impl CameraPlan {
    /// The plan for a render of `count` frames whose first camera is `template`, looking at
    /// `target`, and whose first frame is `first`.
    pub fn new(
        template: Camera,
        target: Vec3,
        motion: MotionSpec,
        follow: Option<Selection>,
        first: &Frame,
        count: usize,
    ) -> Result<CameraPlan, CameraPlanError> {
        let pose = Pose::of_camera(&template, target);
        let motion = match motion {
            MotionSpec::Still => Motion::Still,
            MotionSpec::Orbit { degrees_per_frame } => {
                if !degrees_per_frame.is_finite() {
                    return Err(CameraPlanError::OrbitNotFinite {
                        degrees: degrees_per_frame,
                    });
                }
                Motion::Orbit { degrees_per_frame }
            }
            MotionSpec::OrbitTurns { turns } => {
                if !turns.is_finite() {
                    return Err(CameraPlanError::OrbitTurnsNotFinite { turns });
                }
                Motion::Orbit {
                    degrees_per_frame: 360.0 * turns / count.max(1) as f32,
                }
            }
            MotionSpec::Keyframes(text) => {
                Motion::Keys(Keyframes::parse(&text, &pose).map_err(CameraPlanError::Keyframes)?)
            }
        };
        let follow = match follow {
            None => None,
            Some(sel) => {
                let Some(c) = centre_of(&sel, first).map_err(CameraPlanError::Follow)? else {
                    return Err(CameraPlanError::FollowNoneFirst {
                        selection: sel.text().to_string(),
                    });
                };
                Some((sel, c))
            }
        };
        Ok(CameraPlan {
            template,
            pose,
            motion,
            follow,
        })
    }

    /// The camera of the `k`-th rendered frame (0-based), whose atoms are `frame`.
    pub fn camera(&self, k: usize, frame: &Frame) -> Result<Camera, CameraPlanError> {
        let mut pose = match &self.motion {
            Motion::Still => self.pose,
            Motion::Orbit { degrees_per_frame } => {
                // Reduced in f64 so that frame 100,000 turns as exactly as frame 1.
                let deg = (k as f64 * *degrees_per_frame as f64) % 360.0;
                self.pose.orbit(deg as f32)
            }
            Motion::Keys(keys) => keys.at(k as f32),
        };
        if let Some((sel, c0)) = &self.follow {
            let Some(c) = centre_of(sel, frame).map_err(CameraPlanError::Follow)? else {
                return Err(CameraPlanError::FollowNone {
                    selection: sel.text().to_string(),
                });
            };
            pose = pose.translated(c - *c0);
        }
        if matches!(self.motion, Motion::Still) && self.follow.is_none() {
            return Ok(self.template.clone());
        }
        pose.camera(&self.template)
            .map_err(|error| CameraPlanError::Camera { frame: k, error })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame_at(points: &[[f32; 3]]) -> Frame {
        let mut frame = Frame::new();
        frame.positions = points.to_vec();
        frame
    }

    fn template() -> (Camera, Vec3) {
        let target = Vec3::new(1.0, 2.0, 3.0);
        let eye = target + Vec3::new(0.0, 0.0, 30.0);
        let cam = Camera::perspective_look_at(eye, target, Vec3::Y, 40.0, 64, 48).unwrap();
        (cam, target)
    }

    #[test]
    fn an_orbit_of_k_frames_is_the_pose_turned_by_k_steps() {
        let (cam, target) = template();
        let first = frame_at(&[[0.0; 3]]);
        let motion = MotionSpec::Orbit {
            degrees_per_frame: 7.5,
        };
        let plan = CameraPlan::new(cam.clone(), target, motion, None, &first, 10).unwrap();
        let pose = Pose::of_camera(&cam, target);
        for k in [0usize, 1, 3, 7] {
            let direct = pose.orbit(k as f32 * 7.5).camera(&cam).unwrap();
            assert_eq!(plan.camera(k, &first).unwrap(), direct, "frame {k}");
        }
        // Four turns of a quarter come back to the start, at the same distance throughout.
        let quarter = MotionSpec::OrbitTurns { turns: 1.0 };
        let plan = CameraPlan::new(cam.clone(), target, quarter, None, &first, 4).unwrap();
        for k in 0..=4 {
            let eye = plan.camera(k, &first).unwrap().eye();
            assert!(((eye - target).length() - 30.0).abs() < 1e-3);
        }
        assert!((plan.camera(4, &first).unwrap().eye() - cam.eye()).length() < 1e-3);
        assert!(
            (plan.camera(2, &first).unwrap().eye() - (2.0 * target - cam.eye())).length() < 1e-3
        );
    }

    #[test]
    fn following_translates_the_camera_by_the_centres_move() {
        let (cam, target) = template();
        let first = frame_at(&[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [50.0, 50.0, 50.0]]);
        let follow = Selection::parse("index 0 1").unwrap();
        let plan = CameraPlan::new(
            cam.clone(),
            target,
            MotionSpec::Still,
            Some(follow),
            &first,
            5,
        )
        .unwrap();
        // The followed atoms' centre moves from (1,0,0) to (4,-1,2); the third atom is ignored.
        let later = frame_at(&[[3.0, -2.0, 2.0], [5.0, 0.0, 2.0], [0.0, 0.0, 0.0]]);
        let moved = plan.camera(3, &later).unwrap();
        let d = Vec3::new(3.0, -1.0, 2.0);
        assert!((moved.eye() - (cam.eye() + d)).length() < 1e-4);
        assert!((moved.forward() - cam.forward()).length() < 1e-6);
        assert!((moved.up() - cam.up()).length() < 1e-6);
        // A frame where the selection selects nothing is an error naming it.
        let none = frame_at(&[]);
        assert!(matches!(
            plan.camera(1, &none),
            Err(CameraPlanError::FollowNone { .. })
        ));
    }

    #[test]
    fn non_finite_orbits_are_refused() {
        let (cam, target) = template();
        let first = frame_at(&[[0.0; 3]]);
        let e = CameraPlan::new(
            cam,
            target,
            MotionSpec::Orbit {
                degrees_per_frame: f32::INFINITY,
            },
            None,
            &first,
            2,
        )
        .unwrap_err();
        assert!(matches!(e, CameraPlanError::OrbitNotFinite { .. }));
    }
}
