using System;
using SoftDeca;
using Unity.Collections;
using Unity.Collections.LowLevel.Unsafe;
using UnityEngine;
using UnityEngine.XR.ARFoundation;
using UnityEngine.XR.ARSubsystems;
using UnityEngine.XR.ARKit;

namespace SoftDeca.Unity
{
    /// <summary>
    /// Live face tracking through AR Foundation (ARKit on iOS): blendshape coefficients mapped by
    /// name into the canonical order, and the face mesh (ARFace.vertices, 1,220 vertices) for
    /// SparseSoftDECA through the bundle's landmark profile (z negated back to ARKit's frame), and
    /// the head's and eyes' rotations for SoftDecaHeadAndEyes (mirrored back likewise).
    /// </summary>
    [AddComponentMenu("SoftDECA/AR Face Input")]
    public sealed class ARFaceInput : SoftDecaFaceInput
    {
        public ARFaceManager faceManager;

        private ARFace face;
        private BlendshapeMap map;

        private void OnEnable()
        {
            if (faceManager == null) faceManager = FindAnyObjectByType<ARFaceManager>();
            if (faceManager == null) throw new InvalidOperationException("ARFaceInput needs an ARFaceManager in the scene");
            map = new BlendshapeMap(LocationNamesByValue());
            faceManager.trackablesChanged.AddListener(OnFacesChanged);
        }

        private void OnDisable()
        {
            if (faceManager != null) faceManager.trackablesChanged.RemoveListener(OnFacesChanged);
            face = null;
        }

        // The enum's names at their values: the map then goes by name, whatever the enum's order.
        private static string[] LocationNamesByValue()
        {
            var values = (ARKitBlendShapeLocation[])Enum.GetValues(typeof(ARKitBlendShapeLocation));
            int max = 0;
            foreach (var v in values) max = Math.Max(max, (int)v);
            var names = new string[max + 1];
            foreach (var v in values) names[(int)v] = v.ToString();
            return names;
        }

        private void OnFacesChanged(ARTrackablesChangedEventArgs<ARFace> changes)
        {
            foreach (var f in changes.added) if (face == null) face = f;
            foreach (var removed in changes.removed)
                if (face != null && removed.Key == face.trackableId) face = null;
        }

        public override bool TryGetWeights(float[] weights)
        {
            if (face == null || face.trackingState != TrackingState.Tracking || map == null) return false;
            var subsystem = faceManager.subsystem;
            if (subsystem == null) return false;
            var result = subsystem.TryGetBlendShapes(face.trackableId, Allocator.Temp);
            if (!result.status.IsSuccess()) return false;
            using (NativeArray<XRFaceBlendShape> shapes = result.value)
            {
                for (int i = 0; i < shapes.Length; ++i) map.Set(weights, shapes[i].blendShapeId, shapes[i].coefficient);
            }
            return true;
        }

        /// <summary>
        /// The face anchor's rotation in session space and the eyes' relative to it (ARFace.leftEye,
        /// rightEye), turned back into ARKit's frame: AR Foundation's provider mirrored z.
        /// </summary>
        public override bool TryGetPose(ref FacePose pose)
        {
            if (face == null || face.trackingState != TrackingState.Tracking) return false;
            pose.HasHead = true;
            pose.Head = PoseMath.ArFoundationToArkit(face.transform.localRotation.ToQuat());
            Transform left = face.leftEye, right = face.rightEye;
            pose.HasEyes = left != null && right != null;
            if (pose.HasEyes)
            {
                pose.LeftEye = PoseMath.ArFoundationToArkit(left.localRotation.ToQuat());
                pose.RightEye = PoseMath.ArFoundationToArkit(right.localRotation.ToQuat());
            }
            return true;
        }

        public override unsafe bool TryGetLandmarks(LandmarkInput landmarks)
        {
            if (face == null || face.trackingState != TrackingState.Tracking) return false;
            NativeArray<Vector3> vertices = face.vertices;
            if (vertices.Length != landmarks.ArkitVertexCount) return false;
            landmarks.FromUnity((float*)NativeArrayUnsafeUtility.GetUnsafeReadOnlyPtr(vertices), vertices.Length);
            return true;
        }
    }
}
