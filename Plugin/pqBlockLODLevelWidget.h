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
 * Dragging a marker edits that isovalue as typing it in the Isosurfaces list
 * would: on release, so the panel's Apply (or Auto Apply) runs the filter
 * once per drag, not once per mouse move.
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
class pqMedicalHistogramWidget;
class vtkEventQtSlotConnect;

class pqBlockLODLevelWidget : public pqPropertyGroupWidget
{
  Q_OBJECT
  /// The filter's isovalues (ContourValues), as the histogram marks them.
  Q_PROPERTY(QList<QVariant> contourValues READ contourValues WRITE setContourValues)
  typedef pqPropertyGroupWidget Superclass;

public:
  pqBlockLODLevelWidget(vtkSMProxy* proxy, vtkSMPropertyGroup* group, QWidget* parent = nullptr);
  ~pqBlockLODLevelWidget() override;

  QList<QVariant> contourValues() const;
  void setContourValues(const QList<QVariant>& values);

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
  /// A marker released at a value: that isovalue changes (Apply runs it).
  void setDraggedValue(int index, double value);

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
  vtkEventQtSlotConnect* Connections;
};

#endif
