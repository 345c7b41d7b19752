// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   pqBlockLODLevelWidget
 * @brief   Block LOD Contour's level of detail and its memory estimator.
 *
 * A property-group widget (panel_widget="medical_blocklod_levels") for the
 * level-of-detail properties of Block LOD Contour:
 *
 * - "Auto LOD" (group function AutoLOD);
 * - the level (LOD), disabled while Auto LOD is on, when it shows the level
 *   the last update actually used (ChosenLevel) instead of the setting;
 * - "Memory Budget (MB)" (MemoryBudget), enabled only with Auto LOD;
 * - a table with one row per level (cube edge, estimated triangles, MB and
 *   seconds: EstimatedTriangles, EstimatedMB, EstimatedSeconds), the level
 *   used marked. The estimates are information properties the filter fills
 *   when it runs, so the table changes after Apply.
 *
 * Above them, the histogram of the array contoured (pqMedicalHistogramWidget,
 * counted where the data lives) marks the filter's isovalues (ContourValues).
 * Dragging a marker previews the surface: a second, unregistered Block LOD
 * Contour (the filter's applied properties, the panel's isovalues with the
 * dragged one, level PreviewLevel) drawn in the view in place of the filter's
 * display, re-made and rendered once per pass of the event loop while the
 * mouse moves. Nothing of it enters the undo stack or the filter: on release
 * the preview goes and the isovalue is edited as typing it in the Isosurfaces
 * list would, so Apply (or Auto Apply) runs the filter once per drag, and undo
 * sees one edit; Escape drops the preview and edits nothing.
 *
 * MB are 10^6 bytes, the unit of every memory property of the plugin.
 */
#ifndef pqBlockLODLevelWidget_h
#define pqBlockLODLevelWidget_h

#include "pqPropertyGroupWidget.h"

#include <QList>
#include <QVariant>

class QCheckBox;
class QDoubleSpinBox;
class QLabel;
class QSpinBox;
class QTableWidget;
class QTimer;
class pqMedicalHistogramWidget;
class vtkEventQtSlotConnect;
class vtkSMSourceProxy;
class vtkSMViewProxy;

class pqBlockLODLevelWidget : public pqPropertyGroupWidget
{
  Q_OBJECT
  /// The filter's isovalues (ContourValues), as the histogram marks them.
  Q_PROPERTY(QList<QVariant> contourValues READ contourValues WRITE setContourValues)
  /// Whether a marker drag's preview is drawn in the view (for tests).
  Q_PROPERTY(bool previewing READ isPreviewing)
  typedef pqPropertyGroupWidget Superclass;

public:
  pqBlockLODLevelWidget(vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent = nullptr);
  ~pqBlockLODLevelWidget() override;

  QList<QVariant> contourValues() const;
  void setContourValues(const QList<QVariant>& values);
  bool isPreviewing() const { return this->PreviewRepresentation != nullptr; }

  /// The level a drag's preview is made at: cubes of 4 voxels, coarse enough
  /// to follow the mouse on a CT, fine enough to show the surface's shape.
  static constexpr int PreviewLevel = 1;

Q_SIGNALS:
  void contourValuesChanged();

private Q_SLOTS:
  /// Pulls the estimates from the filter (after it ran), then updateEstimates().
  void pullEstimates();
  /// Refills the table and the level shown from the information properties.
  void updateEstimates();
  /// Enables the level or the budget, as Auto LOD says.
  void updateEnabledState();
  /// Counts the contoured array again (new data, another array).
  void updateHistogram();
  /// A marker released at a value: the preview goes, that isovalue changes (Apply runs it).
  void setDraggedValue(int index, double value);
  /// A marker moved during a drag: the preview takes its value.
  void previewDraggedValue(int index, double value);
  /// Re-makes the preview and renders the view (once per event-loop pass).
  void renderPreview();
  /// The drag cancelled or ended: the preview goes, nothing changes.
  void endPreview();

private:
  Q_DISABLE_COPY(pqBlockLODLevelWidget)

  QCheckBox* AutoLOD;
  QSpinBox* Level;
  QLabel* LevelNote;
  QDoubleSpinBox* MemoryBudget;
  QTableWidget* Table;
  QLabel* Caption;
  pqMedicalHistogramWidget* Histogram;
  QList<QVariant> ContourValues;
  vtkSMSourceProxy* PreviewSource = nullptr;
  vtkSMProxy* PreviewRepresentation = nullptr;
  vtkSMViewProxy* PreviewView = nullptr;
  vtkSMProxy* HiddenRepresentation = nullptr;
  QTimer* PreviewTimer;
  vtkEventQtSlotConnect* Connections;
};

#endif
