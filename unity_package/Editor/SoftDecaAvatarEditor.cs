using System;
using System.Diagnostics;
using System.IO;
using System.Threading.Tasks;
using SoftDeca;
using SoftDeca.Unity;
using UnityEditor;
using UnityEngine;

namespace SoftDeca.Editor
{
    /// <summary>
    /// The inspector of SoftDecaAvatar: the Fit button (fits the user's own mesh to the bundle's
    /// template in the editor and stores the fit as an asset, unless the library judges it poor:
    /// then it shows why and keeps the previous fit) with the fit's report, a slider per
    /// bundle parameter (its range and unit from the bundle), region controls (spheres on the
    /// face, moved in the Scene view), and the component's own fields.
    /// </summary>
    [CustomEditor(typeof(SoftDecaAvatar))]
    public sealed class SoftDecaAvatarEditor : UnityEditor.Editor
    {
        private ParameterInfo[] parameters;
        private string loadedFrom;
        private string loadError;
        private TextAsset reportOf;  // the fit asset whose report is shown
        private FitReport report;
        private FitReport refused;  // the report of a fit just made and refused as poor
        private string fitMessage;

        public override void OnInspectorGUI()
        {
            var avatar = (SoftDecaAvatar)target;
            serializedObject.Update();
            DrawPropertiesExcluding(serializedObject, "parameters", "regions");
            FitSection(avatar);
            LoadParameters(avatar);
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Material", EditorStyles.boldLabel);
            if (loadError != null) EditorGUILayout.HelpBox(loadError, MessageType.Warning);
            if (parameters != null)
                foreach (ParameterInfo p in parameters) ParameterSlider(avatar, p);
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Regions", EditorStyles.boldLabel);
            EditorGUILayout.PropertyField(serializedObject.FindProperty("regions"), true);
            if (serializedObject.ApplyModifiedProperties() || GUI.changed) avatar.MarkMaterialDirty();
        }

        private void LoadParameters(SoftDecaAvatar avatar)
        {
            if (avatar.Model != null)
            {
                parameters = avatar.Model.Parameters;
                return;
            }
            if (loadedFrom == avatar.bundlePath) return;
            loadedFrom = avatar.bundlePath;
            try
            {
                using (var model = Model.Load(avatar.BundleFullPath)) parameters = model.Parameters;
                loadError = null;
            }
            catch (Exception e)
            {
                parameters = null;
                loadError = "The bundle's parameters are not available: " + e.Message;
            }
        }

        // ---- the fit -------------------------------------------------------------------------

        private void FitSection(SoftDecaAvatar avatar)
        {
            EditorGUILayout.Space();
            EditorGUILayout.LabelField("Your avatar", EditorStyles.boldLabel);
            EditorGUI.BeginDisabledGroup(EditorApplication.isPlaying || avatar.SourceMesh == null);
            if (GUILayout.Button(avatar.fit == null ? "Fit" : "Fit again"))
                EditorApplication.delayCall += () =>  // outside the inspector's layout pass
                {
                    Fit(avatar);
                    Repaint();
                };
            EditorGUI.EndDisabledGroup();
            if (fitMessage != null) EditorGUILayout.HelpBox(fitMessage, MessageType.Error);
            if (refused != null) Measures(refused);
            ShowReport(avatar);
        }

        // Fits the renderer's mesh on a worker thread under a progress bar, saves the fit next to
        // the mesh asset and assigns it.
        private void Fit(SoftDecaAvatar avatar)
        {
            const string title = "SoftDECA: fitting the avatar";
            if (avatar == null || avatar.SourceMesh == null) return;  // gone since the click
            Mesh source = avatar.SourceMesh;
            string asset = FitAssetPath(source);
            fitMessage = null;
            refused = null;
            try
            {
                EditorUtility.DisplayProgressBar(title, "Reading " + source.name + " and its ARKit shapes", 0.05f);
                AvatarMesh mesh = SoftDecaAvatar.ReadAvatarMesh(source);
                using (var model = Model.Load(avatar.BundleFullPath))
                {
                    Task<AvatarFit> fitting = Task.Run(() => AvatarFit.Create(model, mesh));
                    var clock = Stopwatch.StartNew();
                    while (!fitting.Wait(100))
                    {
                        double t = clock.Elapsed.TotalSeconds;
                        EditorUtility.DisplayProgressBar(title, "Fitting the template to the face of " + mesh.VertexCount + " vertices (" +
                                                                t.ToString("F0") + " s)", 0.1f + 0.8f * (float)(1 - Math.Exp(-t / 10)));
                    }
                    using (AvatarFit done = fitting.Result)
                    {
                        FitReport made = done.Report();
                        FitQuality quality = made.Quality;
                        if (quality != null && !quality.Passed)
                        {
                            refused = made;
                            fitMessage = "The fit was refused as poor (" + quality.FailedMeasure + "): " + quality.Reason +
                                         (avatar.fit != null ? " The previous fit is kept." : "");
                            return;
                        }
                        EditorUtility.DisplayProgressBar(title, "Saving " + asset, 0.95f);
                        done.Save(Path.GetFullPath(asset));
                        report = made;
                    }
                }
                AssetDatabase.ImportAsset(asset);
                Undo.RecordObject(avatar, "Fit avatar");
                avatar.fit = AssetDatabase.LoadAssetAtPath<TextAsset>(asset);
                reportOf = avatar.fit;
                EditorUtility.SetDirty(avatar);
            }
            catch (Exception e)
            {
                var inner = e is AggregateException && e.InnerException != null ? e.InnerException : e;
                fitMessage = "The fit failed: " + inner.Message;
            }
            finally
            {
                EditorUtility.ClearProgressBar();
            }
        }

        // Next to the mesh's asset (an FBX's folder), else under Assets.
        private static string FitAssetPath(Mesh mesh)
        {
            string meshPath = AssetDatabase.GetAssetPath(mesh);
            string folder = string.IsNullOrEmpty(meshPath) ? "Assets" : Path.GetDirectoryName(meshPath).Replace('\\', '/');
            if (!folder.StartsWith("Assets", StringComparison.Ordinal)) folder = "Assets";  // e.g. a package's read-only mesh
            string name = mesh.name;
            foreach (char c in Path.GetInvalidFileNameChars()) name = name.Replace(c, '_');
            return folder + "/" + name + ".softdeca-fit.bytes";
        }

        // The assigned fit's report: kept from the fit just made, else read from the asset.
        private void ShowReport(SoftDecaAvatar avatar)
        {
            if (avatar.fit == null) return;
            if (reportOf != avatar.fit)
            {
                reportOf = avatar.fit;
                report = null;
                try
                {
                    using (var model = Model.Load(avatar.BundleFullPath))
                    using (AvatarFit saved = AvatarFit.LoadBytes(model, avatar.fit.bytes, Application.temporaryCachePath))
                        report = saved.Report();
                }
                catch (Exception e)
                {
                    fitMessage = "The fit " + avatar.fit.name + " cannot be read: " + e.Message;
                }
            }
            if (report == null) return;
            FitQuality quality = report.Quality;
            if (quality != null && !quality.Passed)
                EditorGUILayout.HelpBox("This fit is poor (" + quality.FailedMeasure + "): " + quality.Reason, MessageType.Warning);
            EditorGUILayout.LabelField("Metres per unit", Format(report.MetresPerUnit, "G4"));
            EditorGUILayout.LabelField("Up axis", report.UpAxis ?? "?");
            EditorGUILayout.LabelField("ARKit shapes", Count(report.ShapesMatched) + " matched, " + Count(report.ShapesCarried) +
                                                       " carried from the template, " + Count(report.ShapesMissing) + " missing");
            if (report.Mirrored) EditorGUILayout.HelpBox("The mesh was exported mirrored (left-handed).", MessageType.Warning);
            Measures(report);
        }

        // The quality measures, each with its bound as the library reports it.
        private static void Measures(FitReport r)
        {
            FitQuality q = r.Quality;
            Func<string, double> bound = name => q == null ? double.NaN : q.Bound(name);
            EditorGUILayout.LabelField("Face covered", Format(100 * r.FaceCoverage, "F0") + " % within " + Format(bound("covered_mm"), "G3") +
                                                           " mm (at least " + Format(100 * bound("face_coverage_min"), "F0") + " %)");
            EditorGUILayout.LabelField("Face to template", Format(r.AvatarToTemplateMmMedian, "F2") + " mm median (at most " +
                                                               Format(bound("avatar_to_template_mm_median_max"), "G3") + "), " +
                                                               Format(r.AvatarToTemplateMmP90, "F2") + " mm 90th percentile (at most " +
                                                               Format(bound("avatar_to_template_mm_p90_max"), "G3") + ")");
            EditorGUILayout.LabelField("Template face size", Format(r.TemplateScale, "F2") + " x the avatar's (" +
                                                                 Format(bound("template_scale_min"), "F2") + " to " +
                                                                 Format(bound("template_scale_max"), "F2") + ")");
            EditorGUILayout.LabelField("Face residual", Format(r.FaceResidualMmMean, "F2") + " mm mean, " +
                                                        Format(r.FaceResidualMmMax, "F2") + " mm largest");
        }

        private static string Count(string[] names) { return names == null ? "?" : names.Length.ToString(); }

        private static string Format(double value, string format)
        {
            return double.IsNaN(value) ? "?" : value.ToString(format, System.Globalization.CultureInfo.InvariantCulture);
        }

        // ---- material ------------------------------------------------------------------------

        private void ParameterSlider(SoftDecaAvatar avatar, ParameterInfo p)
        {
            int at = avatar.parameters.FindIndex(s => s.name == p.Name);
            float current = at >= 0 ? avatar.parameters[at].value : (float)p.DefaultValue;
            string label = string.IsNullOrEmpty(p.Unit) ? p.Name : p.Name + " (" + p.Unit + ")";
            EditorGUILayout.BeginHorizontal();
            float value = EditorGUILayout.Slider(new GUIContent(label, p.Description), current, (float)p.Minimum, (float)p.Maximum);
            bool reset = GUILayout.Button("Default", GUILayout.Width(60));
            EditorGUILayout.EndHorizontal();
            if (reset)
            {
                Undo.RecordObject(avatar, "Reset " + p.Name);
                if (at >= 0) avatar.parameters.RemoveAt(at);
                avatar.MarkMaterialDirty();
            }
            else if (value != current)
            {
                Undo.RecordObject(avatar, "Set " + p.Name);
                var setting = new ParameterSetting { name = p.Name, value = value };
                if (at >= 0) avatar.parameters[at] = setting;
                else avatar.parameters.Add(setting);
                avatar.MarkMaterialDirty();
            }
        }

        private void OnSceneGUI()
        {
            var avatar = (SoftDecaAvatar)target;
            Transform t = avatar.transform;
            for (int i = 0; i < avatar.regions.Count; ++i)
            {
                MaterialRegion r = avatar.regions[i];
                Vector3 world = t.TransformPoint(r.centre);
                Handles.color = new Color(1f, 0.5f, 0.1f, 0.8f);
                EditorGUI.BeginChangeCheck();
                Vector3 moved = Handles.PositionHandle(world, t.rotation);
                float radius = Handles.RadiusHandle(t.rotation, world, r.radius * t.lossyScale.x) / Mathf.Max(t.lossyScale.x, 1e-6f);
                Handles.Label(world, r.parameter + " = " + r.value);
                if (EditorGUI.EndChangeCheck())
                {
                    Undo.RecordObject(avatar, "Move region");
                    r.centre = t.InverseTransformPoint(moved);
                    r.radius = radius;
                    avatar.regions[i] = r;
                    avatar.MarkMaterialDirty();
                }
            }
        }
    }
}
